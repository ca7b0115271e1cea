"""Solve-time benchmark: median and p90 wall time of repeated solves, one row per case.

    .venv/bin/python benchmarks/solve_times.py [--repeats 50] [--only planar,cartesian,franka] [--compare REF]

Each case builds its solver once (build time reported apart), runs one cold solve, then times `repeats`
warm solves with varied goals (cold cases: `repeats` cold solves to new goals). Add a case by adding to
CASES a key (used by --only) and a function that returns a Case.

``--compare REF``: REF is another checkout (e.g. a worktree at main), or a git revision of this repository
(checked out into a temporary worktree for the run); every case runs twice in the same run, each in its own
process, one with this checkout's src/ and one with REF's (same script, same problems), the two processes taking
turns solve by solve so that both see the same machine load; the two rows are printed one under the other ('new'
and 'ref'), or with ``--markdown`` side by side in the speed page's table.

The ``*_workspace_*`` cases solve the preset's sampled workspace set (benchmarks/workspace.py) and list their
slowest solves.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

import comanip
from comanip.planning.planner import SolverOptions

sys.path.insert(0, str(Path(__file__).resolve().parent))
import workspace  # noqa: E402  (the sampled problem sets beside this script)


@dataclass
class Timed:
    """One timed solve: wall time (s), whether it succeeded, its Newton iterations (None where a case does not
    count them) and the problem it solved (a label, for the slowest cases)."""

    seconds: float
    success: bool
    iterations: int | None = None
    problem: str = ""


@dataclass
class Case:
    """One benchmark row: ``solve(k)`` runs the k-th timed solve and returns its :class:`Timed`."""

    name: str
    build_time: float
    solve: Callable[[int], Timed]
    paper_time: float | None = None
    size: int | None = None
    """Problems in the case's set (its solves stop there), None for a case that draws new problems."""


def timed(build: Callable[[], object]) -> tuple[object, float]:
    """(build(), its wall time in s): a case's one-off set-up, reported apart from the solves."""
    t0 = time.perf_counter()
    built = build()
    return built, time.perf_counter() - t0


def reach_case(preset: str, paper_time: float, options: SolverOptions | None = None, label: str = "",
               reach=(0.3, 0.0, 0.0)) -> Callable[[], Case]:
    """Warm solves to goals drawn uniformly within ±5 cm (per axis) of a base goal, each warm-started from
    the previous plan. The base goal is ``reach`` (m) from the body's home position (at rest there); the
    first, cold solve is not timed (it also builds any compiled function)."""

    def make() -> Case:
        model = comanip.presets.load(preset)
        planner, build = timed(lambda: comanip.Planner(model, options))
        rng = np.random.default_rng(0)
        home = model.body.home_position
        start = np.concatenate([home, np.zeros(model.n)])
        base = np.asarray(model.body.kinematics_function(home)[0]).ravel() + np.asarray(reach)[: model.d]
        previous = planner.solve(start, base, model.width)

        def solve(k: int) -> Timed:
            nonlocal previous
            goal = base + rng.uniform(-0.05, 0.05, model.d)
            plan = planner.solve(start, goal, model.width, warm_start=previous)
            previous = plan
            return Timed(plan.solve_time, plan.success, plan.iterations)

        return Case(f"{preset} warm (H={model.H}, n={model.n}){label}", build, solve, paper_time)

    return make


def cold_case(preset: str, paper_time: float | None = None, distances=(0.1, 0.4), moving: bool = False,
              options: SolverOptions | None = None, label: str = "") -> Callable[[], Case]:
    """Cold solves (no warm start) from the home position to goals ``distances`` (m; 0.1–0.4 m) away in
    uniformly drawn directions, a new goal each time (a user's first plan for a goal), at the model's width;
    from rest, or (``moving``) with start velocities uniform in ±0.3 m/s per axis (rad/s per joint for an arm). The planner is fresh: its
    first solves also fill its reach library (comanip.planning.starts.reach_library)."""

    def make() -> Case:
        model = comanip.presets.load(preset)
        planner, build = timed(lambda: comanip.Planner(model, options))
        rng = np.random.default_rng(1)
        home = model.body.home_position
        start = np.concatenate([home, np.zeros(model.n)])
        origin = np.asarray(model.body.kinematics_function(home)[0]).ravel()
        planner.solve(start, origin + 0.2 * np.eye(model.d)[0], model.width)  # any one-off work, untimed

        def solve(k: int) -> Timed:
            direction = rng.normal(size=model.d)
            goal = origin + rng.uniform(*distances) * direction / np.linalg.norm(direction)
            velocity = rng.uniform(-0.3, 0.3, model.n) if moving else np.zeros(model.n)
            plan = planner.solve(np.r_[start[: model.n], velocity], goal, model.width)
            return Timed(plan.solve_time, plan.success, plan.iterations)

        kind = "cold, moving start" if moving else "cold"
        return Case(f"{preset} {kind} (H={model.H}, n={model.n}){label}", build, solve, paper_time)

    return make


def workspace_case(preset: str, warm: bool, moving: bool, paper_time: float | None = None,
                   options: SolverOptions | None = None) -> Callable[[], Case]:
    """The preset's sampled workspace set (benchmarks/workspace.py), its problems at rest or (``moving``) from a
    moving start, in order (solve k is problem k). Cold: a solve to the problem's goal without a
    warm start, by a long-lived planner: a point mass's planner has solved the whole set once before (untimed), which
    fills its reach library as a planner's first solves do (its entries: a full search each). Warm: the plan to the
    problem's goal (untimed), then the timed solve to its warm goal (up to 5 cm away), warm-started from that plan."""

    def make() -> Case:
        model = comanip.presets.load(preset)
        planner, build = timed(lambda: comanip.Planner(model, options))
        problems = [p for p in workspace.load(preset) if p.moving == moving]
        home = model.body.home_position
        origin = np.asarray(model.body.kinematics_function(home)[0]).ravel()
        planner.solve(np.r_[home, np.zeros(model.n)], origin + 0.2 * np.eye(model.d)[0], model.width)  # one-off work
        if not warm and getattr(planner.starts, "library", None) is not None:  # a point mass fills its own; an arm ships its
            for problem in problems:
                planner.solve(problem.start, problem.goal, problem.width)

        def solve(k: int) -> Timed:
            problem = problems[k % len(problems)]
            if warm:
                first = planner.solve(problem.start, problem.goal, problem.width)
                plan = planner.solve(problem.start, problem.warm_goal, problem.width, warm_start=first)
            else:
                plan = planner.solve(problem.start, problem.goal, problem.width)
            return Timed(plan.solve_time, plan.success, plan.iterations, f"#{k % len(problems)} {problem.describe()}")

        kind = ("warm" if warm else "cold") + (", moving start" if moving else ", at rest")
        return Case(f"{preset} workspace {kind} (H={model.H}, n={model.n})", build, solve, paper_time, len(problems))

    return make


def closed_loop_reach_case() -> Case:
    """One closed-loop reach of the transition-data person (planar, 2H = 60 replans, D = 0.3 m, w = 0.02 m):
    the unit of `comanip transition generate` (conditions × trials reaches, spread over the workers)."""
    from comanip.execution import execute_receding_horizon

    model = comanip.presets.planar()
    planner, build = timed(lambda: comanip.Planner(model))
    rng = np.random.default_rng(0)

    def solve(k: int) -> Timed:
        t = time.perf_counter()
        run = execute_receding_horizon(planner, np.zeros(4), [0.3, 0.0], 0.02, steps=2 * model.H, rng=rng)
        return Timed(time.perf_counter() - t, run.failed_replans == 0)

    return Case(f"planar closed-loop reach ({2 * model.H} replans)", build, solve)


def franka_replan_case() -> Case:
    """Replans of closed-loop Franka reaches (the real-time use): from the ready pose to [0.15, 0.1, -0.1] m
    away, replanning at every step from the noisy state until each replan converges, warm from the previous plan
    shifted by one step (:func:`comanip.execution.execute_receding_horizon`). Each row entry is one replan (a success:
    it converged); the first plan of each reach (cold) is left out. Reaches are run as the repeats need them."""
    from comanip.execution import execute_receding_horizon

    model = comanip.presets.load("franka")
    planner, build = timed(lambda: comanip.Planner(model))
    home = model.body.home_position
    start = np.concatenate([home, np.zeros(model.n)])
    goal = np.asarray(model.body.kinematics_function(home)[0]).ravel() + np.array([0.15, 0.1, -0.1])
    records: list[Timed] = []
    rng = np.random.default_rng(0)

    def solve(k: int) -> Timed:
        while len(records) <= k:
            run = execute_receding_horizon(planner, start, goal, rng=rng)
            records.extend(Timed(float(seconds), status == "converged", int(iterations)) for seconds, status, iterations
                           in zip(run.replan_times[1:], run.replan_statuses[1:], run.replan_iterations[1:]))
        return records[k]

    return Case(f"franka closed-loop replan (H={model.H}, n={model.n})", build, solve, 1.3)


def estimate_case(preset: str, reach=(0.3, 0.0, 0.0)) -> Callable[[], Case]:
    """Warm goal estimates (paper Section V-C) from a state observed at 0.2 s of reaches to goals varied
    (±5 cm per axis) around a nominal goal ``reach`` (m) from the body's home position, which is the prior;
    each estimate warm-starts from the previous one. The observed state is drawn from the hidden plan's
    belief at the observed step (motor noise)."""

    def make() -> Case:
        from comanip.estimation import GoalEstimator

        model = comanip.presets.load(preset)
        estimator, build = timed(lambda: GoalEstimator(model))
        rng = np.random.default_rng(0)
        home = model.body.home_position
        start = np.concatenate([home, np.zeros(model.n)])
        nominal = np.asarray(model.body.kinematics_function(home)[0]).ravel() + np.asarray(reach)[: model.d]
        n_o = int(np.floor(0.2 / model.h + 1e-9))
        hidden = estimator.planner.solve(start, nominal)
        previous = estimator.estimate(start, hidden.mean[n_o], 0.2, prior_goal=nominal)

        def solve(k: int) -> Timed:
            nonlocal previous, hidden
            hidden = estimator.planner.solve(start, nominal + rng.uniform(-0.05, 0.05, model.d), warm_start=hidden)
            observed = rng.multivariate_normal(hidden.mean[n_o], hidden.cov[n_o])
            previous = estimator.estimate(start, observed, 0.2, prior_goal=nominal, warm_start=previous)
            return Timed(previous.solve_time, previous.success)

        return Case(f"{preset} estimate_goal warm (t_obs 0.2 s)", build, solve)

    return make


def posterior_case(preset: str, new_start: bool) -> Callable[[], Case]:
    """Posterior over 5 candidate goals 0.1–0.2 m apart from the first 4 observed states of a noisy reach
    to one of them. ``new_start``: each call starts from a different state, so the 5 plans are re-solved
    (warm); otherwise they are reused and a call only scores the observations (a reach in progress). The
    planner is the one ``goal_posterior(model, ...)`` builds (terms compiled, comanip.estimation.model_reaches.estimation_planner)."""

    def make() -> Case:
        from comanip.belief import sample_trajectories
        from comanip.estimation import goal_posterior
        from comanip.estimation.model_reaches.estimation_planner import estimation_planner

        model = comanip.presets.load(preset)
        planner, build = timed(lambda: estimation_planner(model))
        rng = np.random.default_rng(0)
        offsets = np.array([[0, 0, 0], [0, 1, 0], [0, -1, 0], [1, 0, 0], [-1, 0, 0]])[:, : model.d]
        candidates = 0.3 * np.eye(model.d)[0] + 0.15 * offsets
        times = model.h * np.arange(1, 5)
        steps = np.arange(1, 5)
        previous = goal_posterior(planner, np.zeros(2 * model.n), np.zeros((1, 2 * model.n)), [0.0], candidates)

        def solve(k: int) -> Timed:
            nonlocal previous
            start = np.r_[rng.uniform(-0.02, 0.02, model.n), np.zeros(model.n)] if new_start else np.zeros(2 * model.n)
            truth = previous.plans[k % len(candidates)]
            states = sample_trajectories(model.body, model.h, model.kappa, start, truth.torque, 1, rng, model.noise)[0, steps]
            t = time.perf_counter()
            previous = goal_posterior(planner, start, states, times, candidates, warm_start=previous)
            return Timed(time.perf_counter() - t, previous.success)

        label = "5 warm plans" if new_start else "plans reused"
        return Case(f"{preset} goal_posterior, 5 goals ({label})", build, solve)

    return make


COMPILED, UNCOMPILED = SolverOptions(compile=True), SolverOptions(compile=False)
"""Point-mass rows run compiled (what a long-lived planner gets after its background compile, and any planner
for a model compiled before on the machine) or in CasADi's virtual machine (a new model's first seconds); the
default options would give either, depending on the disk cache."""

CASES: dict[str, Callable[[], Case]] = {
    "planar": reach_case("planar", 0.04, COMPILED, " compiled"),
    "cartesian": reach_case("cartesian", 0.20, COMPILED, " compiled"),
    "planar_uncompiled": reach_case("planar", 0.04, UNCOMPILED, " uncompiled"),
    "cartesian_uncompiled": reach_case("cartesian", 0.20, UNCOMPILED, " uncompiled"),
    "planar_ipopt": reach_case("planar", 0.04, SolverOptions(method="ipopt"), " IPOPT"),
    "cartesian_ipopt": reach_case("cartesian", 0.20, SolverOptions(method="ipopt"), " IPOPT"),
    "franka": reach_case("franka", 1.3, reach=(0.15, 0.1, -0.1)),
    "franka_cold": cold_case("franka", 1.3, distances=(0.15, 0.3)),
    "franka_rest": reach_case("franka_rest", 1.3, reach=(0.15, 0.1, -0.1)),
    "franka_rest_cold": cold_case("franka_rest", 1.3, distances=(0.15, 0.3)),
    "franka_rest_cold_moving": cold_case("franka_rest", 1.3, distances=(0.15, 0.3), moving=True),
    "planar_cold": cold_case("planar", 0.04, options=COMPILED, label=" compiled"),
    "cartesian_cold": cold_case("cartesian", 0.20, options=COMPILED, label=" compiled"),
    "planar_cold_uncompiled": cold_case("planar", 0.04, options=UNCOMPILED, label=" uncompiled"),
    "planar_cold_ipopt": cold_case("planar", 0.04, options=SolverOptions(method="ipopt"), label=" IPOPT"),
    "cartesian_cold_ipopt": cold_case("cartesian", 0.20, options=SolverOptions(method="ipopt"), label=" IPOPT"),
    "cartesian_cold_uncompiled": cold_case("cartesian", 0.20, options=UNCOMPILED, label=" uncompiled"),
    "human": reach_case("human", None, COMPILED, " compiled"),
    "human_cold": cold_case("human", options=COMPILED, label=" compiled"),
    "human_cartesian": reach_case("human_cartesian", None, COMPILED, " compiled"),
    "human_cartesian_cold": cold_case("human_cartesian", options=COMPILED, label=" compiled"),
    "planar_cold_moving": cold_case("planar", moving=True, options=COMPILED, label=" compiled"),
    "cartesian_cold_moving": cold_case("cartesian", moving=True, options=COMPILED, label=" compiled"),
    "human_cold_moving": cold_case("human", moving=True, options=COMPILED, label=" compiled"),
    "human_cartesian_cold_moving": cold_case("human_cartesian", moving=True, options=COMPILED, label=" compiled"),
    **{f"{preset}_workspace_{kind}{suffix}": workspace_case(preset, kind == "warm", suffix == "_moving", paper,
                                                           None if preset in workspace.ARM_PRESETS else COMPILED)
       for preset, paper in (("planar", 0.04), ("cartesian", 0.20), ("human", None), ("human_cartesian", None),
                             ("franka", 1.3), ("franka_rest", 1.3))
       for kind in ("cold", "warm") for suffix in ("", "_moving")},
    "closed_loop": closed_loop_reach_case,
    "franka_replan": franka_replan_case,
    "estimate_planar": estimate_case("planar"),
    "estimate_cartesian": estimate_case("cartesian"),
    "estimate_franka": estimate_case("franka", reach=(0.15, 0.1, -0.1)),
    "posterior_cartesian": posterior_case("cartesian", new_start=True),
    "posterior_cartesian_update": posterior_case("cartesian", new_start=False),
}


HEADER = (f"{'case':<58} {'build s':>8} {'median ms':>10} {'p90 ms':>8} {'it med':>7} {'it p90':>7} {'ok':>7} "
          f"{'paper ms':>9} {'speed-up':>9}")
SLOWEST = 3
"""Slowest solves listed per case."""


def measure_case(key: str, repeats: int) -> dict:
    """The case timed in this process (:func:`summary`)."""
    case = CASES[key]()
    count = repeats if case.size is None else min(repeats, case.size)
    return summary(case.name, case.build_time, case.paper_time, [case.solve(k) for k in range(count)])


def summary(name: str, build_time: float, paper_time: float | None, runs: list[Timed]) -> dict:
    """A row from its solves: name, build_s, median_s, p90_s, iterations (median, p90; None if not counted), ok,
    runs, paper_s, the ``SLOWEST`` solves (seconds, iterations, problem) and every solve's iterations (counted)."""
    times = np.array([run.seconds for run in runs])
    counted = [run.iterations for run in runs if run.iterations is not None]
    iterations = (float(np.median(counted)), float(np.percentile(counted, 90))) if counted else None
    slowest = [(run.seconds, run.iterations, run.problem) for run in sorted(runs, key=lambda run: -run.seconds)[:SLOWEST]]
    return {"name": name, "build_s": build_time, "median_s": float(np.median(times)),
            "p90_s": float(np.percentile(times, 90)), "iterations": iterations, "ok": int(sum(run.success for run in runs)),
            "runs": len(runs), "paper_s": paper_time, "slowest": slowest, "counted": counted}


def whole_workspace_lines(rows: list[dict]) -> list[str]:
    """Per preset whose two cold workspace cases (at rest, moving start) are both among ``rows``: the Newton
    iterations of a cold solve over the whole set, median / p90 and their ratio (no slow corner: p90 within twice the
    median)."""
    cold = {}
    for row in rows:
        preset, _, kind = row["name"].partition(" workspace cold, ")
        if kind and row["counted"]:
            cold.setdefault(preset, []).append(row["counted"])
    lines = []
    for preset, parts in cold.items():
        if len(parts) == 2:
            counted = np.concatenate(parts)
            median, p90 = np.median(counted), np.percentile(counted, 90)
            lines.append(f"- {preset}: {median:.0f} / {p90:.0f} iterations over {len(counted)} problems, "
                         f"p90 {p90 / median:.1f} × the median")
    return lines


def text_row(row: dict) -> str:
    paper, iterations = row["paper_s"], row["iterations"] or (np.nan, np.nan)
    return (f"{row['name']:<58} {row['build_s']:8.2f} {1e3 * row['median_s']:10.2f} {1e3 * row['p90_s']:8.2f} "
            f"{iterations[0]:7.1f} {iterations[1]:7.1f} {row['ok']:>3}/{row['runs']:<3} "
            + (f"{1e3 * paper:9.0f} {paper / row['median_s']:8.1f}x" if paper else f"{'-':>9} {'-':>9}"))


def slowest_lines(row: dict) -> list[str]:
    """The row's slowest solves, one a line (problem label where the case names its problems)."""
    return [f"    slowest: {_time(seconds)}, {iterations} it, {problem}" for seconds, iterations, problem in row["slowest"]
            if problem]


def _time(seconds: float) -> str:
    return f"{seconds:.2f} s" if seconds >= 0.1 else f"{1e3 * seconds:.1f} ms"


def markdown_table(rows: list[dict], repeats: int) -> str:
    """The README's speed block: one row per case, medians of ``repeats`` solves; then the slowest solves of the
    workspace cases."""
    lines = [f"Measured by `benchmarks/solve_times.py --markdown --repeats {repeats} --only …` (median and p90 of "
             f"{repeats} solves per case, or of every problem of a workspace set; successes count plans that reach their goal):", "",
             "| case | median | p90 | iterations, median / p90 | succeeded | paper |", "|---|---|---|---|---|---|"]
    for row in rows:
        iterations = "–" if row["iterations"] is None else f"{row['iterations'][0]:.0f} / {row['iterations'][1]:.0f}"
        lines.append(f"| {row['name']} | {_time(row['median_s'])} | {_time(row['p90_s'])} | {iterations} | "
                     f"{row['ok']}/{row['runs']} | {_time(row['paper_s']) if row['paper_s'] else '–'} |")
    pooled = whole_workspace_lines(rows)
    if pooled:
        lines += ["", "Cold solves over each whole workspace set, at rest and moving (Newton iterations, median / p90):", ""] + pooled
    listed = [row for row in rows if any(problem for *_, problem in row["slowest"])]
    if listed:
        lines += ["", f"The {SLOWEST} slowest solves of each workspace case (D: goal distance, w: width, v0: start speed):", ""]
        for row in listed:
            lines.append(f"- {row['name']}: " + "; ".join(f"{_time(seconds)} ({iterations} it, {problem})"
                                                         for seconds, iterations, problem in row["slowest"]))
    return "\n".join(lines)


def markdown_comparison(pairs: list[tuple[dict, dict]], repeats: int, reference: str) -> str:
    """The speed page's side-by-side block: per case this code's row and the reference's (:func:`measure_side_by_side`),
    then the slowest solves of each."""
    lines = [f"Measured by `benchmarks/solve_times.py --markdown --repeats {repeats} --compare {reference} --only …` "
             f"(median and p90 of {repeats} solves per case, or of every problem of a workspace set; this code and the code at {reference} in their own "
             "processes, taking turns solve by solve; successes count plans that reach their goal):", "",
             "| case | median | p90 | iterations, median / p90 | succeeded | previous median | previous p90 | "
             "previous iterations | previous succeeded |", "|---|---|---|---|---|---|---|---|---|"]

    def iterations(row):
        return "–" if row["iterations"] is None else f"{row['iterations'][0]:.0f} / {row['iterations'][1]:.0f}"

    for new, ref in pairs:
        lines.append(f"| {new['name']} | {_time(new['median_s'])} | {_time(new['p90_s'])} | {iterations(new)} | "
                     f"{new['ok']}/{new['runs']} | {_time(ref['median_s'])} | {_time(ref['p90_s'])} | {iterations(ref)} | "
                     f"{ref['ok']}/{ref['runs']} |")
    for label, side in (("this code", 0), ("the previous code", 1)):
        pooled = whole_workspace_lines([pair[side] for pair in pairs])
        if pooled:
            lines += ["", f"Cold solves over each whole workspace set, at rest and moving, {label} (Newton iterations, "
                      "median / p90):", ""] + pooled
    lines += ["", f"The {SLOWEST} slowest solves of each case, this code (D: goal distance, w: width, v0: start speed):", ""]
    for new, _ in pairs:
        lines.append(f"- {new['name']}: " + "; ".join(f"{_time(seconds)} ({iterations} it, {problem})"
                                                     for seconds, iterations, problem in new["slowest"]))
    return "\n".join(lines)


def reference_source(compare: str) -> tuple[Path, Callable[[], None]]:
    """The ``src`` of the checkout to compare with, and how to clean up after: ``compare`` is a checkout's folder,
    or else a git revision of this repository, checked out into a temporary worktree for the run."""
    if Path(compare).is_dir():
        return Path(compare).resolve() / "src", lambda: None
    import tempfile

    root = Path(__file__).resolve().parents[1]
    folder = Path(tempfile.mkdtemp(prefix="comanip-reference-")) / "checkout"
    subprocess.run(["git", "-C", str(root), "worktree", "add", "--detach", str(folder), compare], check=True,
                   capture_output=True)
    return folder / "src", lambda: subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(folder)],
                                                  check=True, capture_output=True)


def measure_side_by_side(sources: list[Path], key: str, repeats: int) -> list[dict]:
    """The case timed once per checkout, each in a fresh process importing comanip from its ``src``; the
    processes take turns solve by solve (solve k of every checkout, then solve k + 1)."""
    workers = [subprocess.Popen([sys.executable, __file__, "--only", key, "--serve"], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(src)})
               for src in sources]
    heads = [worker_reply(worker) for worker in workers]  # each has built its case
    runs = [[] for _ in workers]
    for k in range(repeats if heads[0]["size"] is None else min(repeats, heads[0]["size"])):
        for worker, run in zip(workers, runs):
            worker.stdin.write(f"{k}\n")
            worker.stdin.flush()
            run.append(Timed(*worker_reply(worker)))
    for worker in workers:
        worker.stdin.close()
        worker.wait()
    return [summary(head["name"], head["build_s"], head["paper_s"], run) for head, run in zip(heads, runs)]


def worker_reply(worker: subprocess.Popen):
    """The next JSON line a ``--serve`` process writes (other output on its stdout is skipped)."""
    while True:
        line = worker.stdout.readline()
        if not line:
            raise RuntimeError(f"benchmark process {worker.args} ended early (exit code {worker.wait()})")
        if line.startswith(("{", "[")):
            return json.loads(line)


def serve(key: str) -> None:
    """Build the case, write its name and build time, then time solve k for every k read from stdin."""
    case = CASES[key]()
    print(json.dumps({"name": case.name, "build_s": case.build_time, "paper_s": case.paper_time, "size": case.size}),
          flush=True)
    for line in sys.stdin:
        run = case.solve(int(line))
        print(json.dumps([run.seconds, bool(run.success), run.iterations, run.problem]), flush=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=50)
    parser.add_argument("--only", default="", help=f"comma-separated case keys to run, of: {', '.join(CASES)}")
    parser.add_argument("--compare", default=None,
                        help="another checkout to time side by side (its src/), or a git revision of this repository")
    parser.add_argument("--markdown", action="store_true",
                        help="print the README's markdown table instead (with --compare: the side-by-side table)")
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    wanted = [w for w in args.only.split(",") if w]
    unknown = [w for w in wanted if w not in CASES]
    if unknown:
        raise SystemExit(f"unknown case keys {unknown}; the cases are {', '.join(CASES)}")
    keys = [key for key in CASES if not wanted or key in wanted]
    if args.serve:
        serve(keys[0])
        return
    if args.markdown and args.compare is not None:
        source, clean_up = reference_source(args.compare)
        try:
            pairs = []
            for key in keys:
                pairs.append(tuple(measure_side_by_side([Path(__file__).resolve().parents[1] / "src", source], key,
                                                        args.repeats)))
                print(text_row(pairs[-1][0]), file=sys.stderr, flush=True)   # progress
        finally:
            clean_up()
        print(markdown_comparison(pairs, args.repeats, args.compare).replace("--only …", "--only " + ",".join(keys)))
        return
    if args.markdown:
        rows = []
        for key in keys:
            rows.append(measure_case(key, args.repeats))
            print(text_row(rows[-1]), file=sys.stderr, flush=True)   # progress
        print(markdown_table(rows, args.repeats).replace("--only …", "--only " + ",".join(keys)))
        return
    if args.compare is None:
        print(HEADER)
        for key in keys:
            row = measure_case(key, args.repeats)
            print("\n".join([text_row(row)] + slowest_lines(row)), flush=True)
        return
    here = Path(__file__).resolve().parents[1] / "src"
    source, clean_up = reference_source(args.compare)
    print(f"{'code':<5}{HEADER}")
    try:
        for key in keys:
            rows = measure_side_by_side([here, source], key, args.repeats)
            for label, row in zip(("new", "ref"), rows):
                print("\n".join([f"{label:<5}{text_row(row)}"] + slowest_lines(row)), flush=True)
    finally:
        clean_up()


if __name__ == "__main__":
    main()
