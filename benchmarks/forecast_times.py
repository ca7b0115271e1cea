"""Update times of the online estimator with its forecast of the hand, and of the forecast alone.

    .venv/bin/python benchmarks/forecast_times.py [--reaches 40] [--presets arm,human_cartesian,planar] [--repeats 3]
                                                  [--stages] [--compare REF] [--markdown]

Each preset's estimator follows reaches sampled from the model's own noise (open loop) from rest to goals
0.1–0.6 m away in random directions, observed at 125 Hz, with the shipped people model; the recorded arm
reaches (``../shared/data/arm_reaches``, when beside the clone) are streamed as a tracker delivers them (125 Hz,
from 0.15 s before the onset), and for 2-D presets the ``cursory`` mouse movements' development split (the ``data``
extra) as recorded (100 Hz). Every update is timed (wall and process CPU time: the other jobs on a shared machine
inflate the CPU time less), and the forecast alone (``continued_reach`` on the same inputs) right after it.
Printed per preset and source: median, p95, p99 and largest update; the first update of each reach (the
estimator's first) and the first informative one (the first whose estimate is not the prior: the hand has left its
start, where an explanation solves cold); the forecast alone; and the slowest updates with the stage that took
longest. ``--stages`` adds where an update spends its time: each explanation of the estimator's chain (the time of
its ``explain``, in the updates that ask it) and the rest of the update (the estimate from the explanation's answer,
the smoothed goal, the forecast), each stage's median and p95 over the updates that run it and its share of all update
time. ``--compare REF`` runs every source a second time with the code of another checkout REF (a folder, or a git
revision checked out for the run), each in its own process, the two taking turns reach by reach, and prints both.
"""

from __future__ import annotations

import argparse
import inspect
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from solve_times import reference_source, worker_reply  # noqa: E402  (beside this script)

ARMS = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
SLOWEST = 3
"""Slowest updates listed per preset and source."""


def sampled_reaches(model, count: int, rng):
    """(t, positions, velocities) of ``count`` reaches from the model's own noise, at 125 Hz."""
    import comanip
    from comanip.belief import sample_trajectories
    planner = comanip.Planner(model)
    reaches = []
    for _ in range(count):
        direction = rng.normal(size=model.d)
        goal = rng.uniform(0.1, 0.6) * direction / np.linalg.norm(direction)
        plan = planner.solve(np.zeros(model.state_size), goal, model.width)
        states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
        t = np.arange(0.008, plan.t[-1], 0.008)
        position = np.array([np.interp(t, plan.t, states[:, k]) for k in range(model.n)]).T
        velocity = np.array([np.interp(t, plan.t, states[:, model.n + k]) for k in range(model.n)]).T
        reaches.append((t, position, velocity))
    return reaches


def recorded_reaches(limit: int):
    from comanip.recordings import load_tathum
    return [(r.t, r.position, r.velocity) for r in (trial.streamed_recording() for trial in load_tathum(ARMS)[:limit])]


def recorded_mouse_movements(limit: int):
    """The first ``limit`` movements of the ``cursory`` development split (the ``data`` extra), or [] without it."""
    try:
        from comanip.recordings import load_cursory
        recordings = load_cursory("development")[:limit]
    except ImportError:
        return []
    return [(r.t, r.position, r.velocity) for r in recordings]


def sources(name: str, count: int, seed: int) -> list[tuple[str, list]]:
    """[(source label, reaches)] of one preset: its own sampled reaches, and the recorded ones of its kind."""
    import comanip
    model = comanip.presets.load(name)
    # one seed per preset, so that a worker of another checkout draws the same reaches
    found = [("sampled", sampled_reaches(model, count, np.random.default_rng([seed, sum(map(ord, name))])))]
    if model.d == 3 and ARMS.is_dir():
        found.append(("recorded arms", recorded_reaches(count)))
    if model.d == 2 and (mouse := recorded_mouse_movements(count)):
        found.append(("recorded mouse", mouse))
    return found


STAGE_NAMES = {"HandAtRest": "the hand at rest", "Vetoed": "the model at its own pace, with its vetoes",
               "ModelAtOwnPace": "the model at its own pace", "ModelAtPersonPace": "the model at the person's pace",
               "RecordedPeople": "recorded people (the people model)"}
"""Readable names of the default chain's explanations (others keep their class name)."""
REST = "the rest (estimate, smoothing, forecast)"
"""The stage of an update outside its explanations."""


def timed_stage(explanation, stage_times: list):
    """Make ``explanation.explain`` append its wall time (s) to ``stage_times`` as (stage name, s)."""
    explain = explanation.explain
    name = STAGE_NAMES.get(type(explanation).__name__, type(explanation).__name__)

    def timed(hand, latest):
        begin = time.perf_counter()
        explained = explain(hand, latest)
        stage_times.append((name, time.perf_counter() - begin))
        return explained
    explanation.explain = timed


def timed_reach(model, reach, stages: dict | None = None) -> list[tuple]:
    """[(wall s, cpu s, forecast alone s, update index, informative, its longest stage or "")] of every update of one
    reach, a fresh estimator for it; with ``stages`` (a dict), each stage's wall times (s) are appended to
    ``stages[name]`` ("the rest": the update less its explanations)."""
    import comanip
    from comanip.estimation.forecast.hand_forecast import continued_reach
    t, position, velocity = reach
    estimator = comanip.OnlineGoalEstimator(model, np.r_[position[0], np.zeros(model.state_size - model.n)])
    # a checkout from before the family held the model's step map passes it to the forecast
    older = [estimator.transition] if "transition" in inspect.signature(continued_reach).parameters else []
    asked: list = []
    if stages is not None:
        for explanation in estimator.explanations:
            timed_stage(explanation, asked)
    out = []
    for k in range(len(t)):
        asked.clear()
        wall, cpu = time.perf_counter(), time.process_time()
        estimate = estimator.update(float(t[k] - t[0]), position[k], velocity[k])
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        longest = ""
        if stages is not None:
            parts = asked + [(REST, wall - sum(seconds for _, seconds in asked))]
            for name, seconds in parts:
                stages.setdefault(name, []).append(seconds)
            name, seconds = max(parts, key=lambda pair: pair[1])
            longest = f"{name} {1e3 * seconds:.1f} ms"
        forecast = estimate.forecast
        begin = time.perf_counter()
        continued_reach(estimator.family, *older, estimator.start_position, estimate.t_obs, position[k], velocity[k],
                        estimate.goal, estimate.goal_covariance, forecast.stop_time)
        out.append((wall, cpu, time.perf_counter() - begin, k, str(estimate.status) != "uninformative", longest))
    return out


def summary(label: str, updates_per_reach: list[list[tuple]], stages: dict | None) -> dict:
    """The numbers of one preset and source from :func:`timed_reach`'s rows of each reach."""
    rows = [row for reach in updates_per_reach for row in reach]
    wall = 1e3 * np.array([row[0] for row in rows])
    first = 1e3 * np.array([reach[0][0] for reach in updates_per_reach])
    informative = 1e3 * np.array([next((row[0] for row in reach if row[4]), np.nan) for reach in updates_per_reach])
    informative = informative[np.isfinite(informative)]
    order = np.argsort(wall)[::-1][:SLOWEST]
    return {"label": label, "reaches": len(updates_per_reach), "updates": len(rows),
            "wall": [float(np.median(wall)), float(np.percentile(wall, 95)), float(np.percentile(wall, 99)), float(wall.max())],
            "cpu": [float(np.median(1e3 * np.array([r[1] for r in rows]))), float(np.percentile(1e3 * np.array([r[1] for r in rows]), 95))],
            "first": [float(np.median(first)), float(np.percentile(first, 95)), float(first.max())],
            "informative": [float(np.median(informative)), float(np.percentile(informative, 95)), float(informative.max())]
            if len(informative) else None,
            "forecast": [float(np.median(1e3 * np.array([r[2] for r in rows]))), float(np.percentile(1e3 * np.array([r[2] for r in rows]), 95))],
            "slowest": [f"{wall[i]:.1f} ms at update {rows[i][3]}" + (f" ({rows[i][5]})" if rows[i][5] else "") for i in order],
            "stages": None if stages is None else
            {name: [1e3 * float(np.median(v)), 1e3 * float(np.percentile(v, 95)), float(np.sum(v)) / (wall.sum() / 1e3), len(v)]
             for name, v in stages.items()}}


def serve(presets: list[str], count: int, seed: int, with_stages: bool) -> None:
    """A worker: build every source, write their labels and sizes, then for each 'source index, reach index' read
    from stdin time that reach and write its rows; 'done SOURCE' writes that source's stage times."""
    import comanip
    built = [(comanip.presets.load(name), f"{name} ({label})", reaches) for name in presets
             for label, reaches in sources(name, count, seed)]
    stages = [{} if with_stages else None for _ in built]
    print(json.dumps([[label, len(reaches)] for _, label, reaches in built]), flush=True)
    for line in sys.stdin:
        which, k = (int(word) for word in line.split())
        model, _, reaches = built[which]
        print(json.dumps(timed_reach(model, reaches[k], stages[which])), flush=True)
        if k == len(reaches) - 1:
            print(json.dumps(stages[which] or {}), flush=True)   # one JSON object, stages timed or not


def measure(srcs: list[Path], presets: list[str], count: int, repeats: int, seed: int, with_stages: bool) -> list[list[dict]]:
    """Per checkout (``srcs``), the summary of every preset and source; the checkouts' workers take turns reach by
    reach, ``repeats`` times over each source."""
    args = [sys.executable, __file__, "--serve", "--presets", ",".join(presets), "--reaches", str(count), "--seed", str(seed)]
    workers = [subprocess.Popen(args + (["--stages"] if with_stages else []), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                text=True, env={**os.environ, "PYTHONPATH": str(src)}) for src in srcs]
    heads = [worker_reply(worker) for worker in workers]
    out = [[] for _ in workers]
    for which, (label, size) in enumerate(heads[0]):
        per_reach, stages = [[] for _ in workers], [None for _ in workers]
        for _ in range(repeats):
            for k in range(size):
                for w, worker in enumerate(workers):
                    worker.stdin.write(f"{which} {k}\n")
                    worker.stdin.flush()
                    per_reach[w].append(worker_reply(worker))
                    if k == size - 1:
                        stages[w] = worker_reply(worker)
        for w in range(len(workers)):
            out[w].append(summary(label, per_reach[w], stages[w] if with_stages else None))
        print(f"  {label}: done", file=sys.stderr, flush=True)
    for worker in workers:
        worker.stdin.close()
        worker.wait()
    return out


def markdown(results: list[list[dict]], names: list[str], command: str) -> str:
    """The tables: update times per checkout, the slowest updates, and with stages where an update spends its time."""
    load = os.getloadavg()[0]
    lines = [f"Measured by `{command}` (1-minute load average at the end {load:.2f}); ms, wall time:", "",
             "| preset (source) | code | reaches | updates | update median / p95 / p99 / largest | CPU median / p95 | "
             "first update of a reach, median / p95 / largest | first informative update, median / p95 / largest | "
             "forecast alone, median / p95 |", "|---|---|---|---|---|---|---|---|---|"]
    for rows in zip(*results):
        for name, row in zip(names, rows):
            informative = "–" if row["informative"] is None else " / ".join(f"{v:.2f}" for v in row["informative"])
            lines.append(f"| {row['label']} | {name} | {row['reaches']} | {row['updates']} | "
                         + " / ".join(f"{v:.2f}" for v in row["wall"]) + " | " + " / ".join(f"{v:.2f}" for v in row["cpu"])
                         + " | " + " / ".join(f"{v:.2f}" for v in row["first"]) + f" | {informative} | "
                         + " / ".join(f"{v:.2f}" for v in row["forecast"]) + " |")
    lines += ["", "Slowest updates (with the stage that took longest where stages were timed):", ""]
    for rows in zip(*results):
        for name, row in zip(names, rows):
            lines.append(f"- {row['label']}, {name}: " + "; ".join(row["slowest"]))
    if results[0][0]["stages"] is not None:
        lines += ["", "Where an update spends its time (wall; each stage over the updates that run it):", "",
                  "| preset (source) | code | stage | updates | median / p95 (ms) | share of all update time |",
                  "|---|---|---|---|---|---|"]
        for rows in zip(*results):
            for name, row in zip(names, rows):
                for stage, (median, p95, share, count) in row["stages"].items():
                    lines.append(f"| {row['label']} | {name} | {stage} | {count} | {median:.2f} / {p95:.2f} | {100 * share:.0f} % |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reaches", type=int, default=40)
    parser.add_argument("--presets", default="arm,human_cartesian,planar")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--stages", action="store_true", help="also print where an update spends its time")
    parser.add_argument("--compare", default=None, help="another checkout (its folder) or a git revision to time beside this code")
    parser.add_argument("--markdown", action="store_true", help="print only the tables (progress on stderr)")
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    presets = [name for name in args.presets.split(",") if name]
    if args.serve:
        serve(presets, args.reaches, args.seed, args.stages)
        return
    here = Path(__file__).resolve().parents[1] / "src"
    command = "benchmarks/forecast_times.py " + " ".join(argv if argv is not None else sys.argv[1:])
    if args.compare is None:
        print(markdown(measure([here], presets, args.reaches, args.repeats, args.seed, args.stages), ["this code"], command))
        return
    source, clean_up = reference_source(args.compare)
    try:
        results = measure([here, source], presets, args.reaches, args.repeats, args.seed, args.stages)
    finally:
        clean_up()
    print(markdown(results, ["this code", f"previous ({args.compare})"], command))


if __name__ == "__main__":
    main()
