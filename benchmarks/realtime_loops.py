"""Closed loops at a robot's rate, replanned on a per-cycle budget, against the same loops replanned to convergence.

    .venv/bin/python benchmarks/realtime_loops.py [--presets franka_rest,planar] [--problems 20] [--rate 100|step]
                                                  [--compare REF] [--markdown]

Problems: ``--problems`` spread evenly over each preset's workspace set (``benchmarks/workspace/<preset>.json``: the
Panda from its ready pose to goals 0.1–0.3 m away, point masses from the origin to goals 0.05–0.8 m away, widths
5–50 mm, starts at rest and moving); each problem's goal jumps once, at 30 % of the horizon H·h, by 5 cm (even
problems) or 20 cm (odd) in a seeded random direction (for an arm, to a goal it reaches). Every loop runs
1.5·H·h seconds at ``--rate`` Hz (``step``: a cycle of the preset's own step h), its first plan a full (cold) solve from the start, every later cycle warm from the
previous plan shifted by the cycle; once with motor noise (the same noise seed for every loop of a problem) and once
without, where the loops differ by their replanning alone (with noise, one run's cost moves by percents with the
noise it meets, so the noisy rows compare sums over many problems).

Loops, taking turns problem by problem in one process:

- ``converged``: every cycle's replan runs until it converges (the reference);
- ``1 iteration``: one Newton iteration per cycle (``Replanner(planner, iterations=1)``);
- ``budget``: as many iterations as a wall budget per cycle allows, every cost in it (``--budget``: 5 ms for arms,
  1 ms for point masses);
- ``full solve, budget``: the code before the real-time replanner, ``Planner.solve`` warm from the shifted plan with
  ``max_wall_time`` the same budget, its per-solve set-up (the reachability witness, the start policy) in every cycle.

Per preset and loop: the executed cost (:func:`comanip.execution.executed_cost`) against the converged loop's on the
same problem, in units of the objective's scale |J_best(w)| (the best attainable J, the solver's normaliser; the
converged loop's own J can be near zero, where a ratio to it says nothing): the mean over the problems of
(J - J_converged) / |J_best| and the largest (lower is better); reach
successes (the hand within w of the final goal at the end); how far the hand ends from where the converged loop's
ends (the largest over the problems); every cycle's wall time after the first plan, from the
measured state to tau_0 (median, p99, largest), the wall time per Newton iteration of the cycles that iterated (their
set-up included: median), the preparation of the next cycle that each cycle runs after sending tau_0
(:meth:`Replanner.prepare`: median, p99), the p99 of a cycle's time with its preparation (what must fit the control
period) and the first plans' (cold, median); the share of cycles flagged 'not_contracting'; and the slowest cycles.
Wall times are of the machine this runs on, with its load (the 1-minute load average is printed).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

import comanip
from comanip.execution import Observation, execute_receding_horizon, executed_cost
from comanip.optim import Progress
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.replanner import Replan, Replanner, shifted_torques
from comanip.planning.solver_options import SolverOptions

sys.path.insert(0, str(Path(__file__).resolve().parent))
import workspace  # noqa: E402  (the sampled problem sets beside this script)
from solve_times import reference_source  # noqa: E402

JUMPS = (0.05, 0.2)
"""Goal jumps (m), alternating over the problems."""
JUMP_AT = 0.3
"""When the goal jumps, as a share of the horizon H·h."""
RUN_LENGTH = 1.5
"""A loop's duration in horizons H·h."""
BUDGETS = {"arm": 0.005, "point mass": 0.001}
"""Default wall budget per cycle (s), and the target of every cycle's p99 wall time."""
COST_TARGET = 0.001
"""The target of a real-time loop's executed cost: no more than this above the converged loop's (in units of |J_best|,
the mean over the problems, with motor noise)."""
WORST_COST_TARGET, FINAL_HAND_TARGET = 0.002, 0.001
"""The targets of a real-time loop without motor noise, on every problem: its executed cost no more than this above
the converged loop's (of |J_best|), its hand ending within this of where the converged loop's ends (m)."""
REAL_TIME_LOOPS = ("1 iteration", "budget")
PLURALS = {"arm": "arms", "point mass": "point masses"}
SLOWEST = 3
EXACT_STATE = Observation(0.0, 0.0)
"""The loops replan from the state itself, as a robot that measures its joints (a model's own observation model, the
person's delayed sight, is left out)."""


class BudgetedFullSolves:
    """The replanning before :class:`Replanner`: a full warm :meth:`Planner.solve` per cycle from the previous plan
    shifted to the cycle, with ``max_wall_time``."""

    def __init__(self, planner: comanip.Planner, max_wall_time: float):
        self.planner, self.max_wall_time = planner, max_wall_time

    def first_plan(self, start, goal, width=None) -> Replan:
        return Replan.of_plan(self.planner.solve(start, goal, width))

    def replan(self, previous: Replan, state, elapsed: float, goal=None, width=None) -> Replan:
        began = time.perf_counter()
        warm = shifted_torques(previous.torque, elapsed / self.planner.model.h)
        plan = self.planner.solve(state, goal, width, warm_start=warm, max_wall_time=self.max_wall_time)
        # a budgeted full solve says nothing of contraction: one that did not converge is flagged 'not_contracting'
        return Replan.of_plan(plan, wall_time=time.perf_counter() - began)

    def prepare(self, replan: Replan, elapsed: float) -> float:
        """Nothing: a full solve prepares nothing for the next."""
        return 0.0


@dataclass
class LoopRuns:
    """One loop's runs over a preset's problems."""

    costs: list[float] = field(default_factory=list)
    scales: list[float] = field(default_factory=list)
    """|J_best(w)| of each problem (the objective's scale at its width)."""
    successes: list[bool] = field(default_factory=list)
    final_hands: list[np.ndarray] = field(default_factory=list)
    """Per problem, the hand's position at the end (d,), m."""
    cycle_times: list[np.ndarray] = field(default_factory=list)
    """Per problem, its cycles' wall times after the first plan (s), from the state to tau_0."""
    preparation_times: list[np.ndarray] = field(default_factory=list)
    """Per problem, the wall times of its cycles' preparations of the next cycle (s), after tau_0, the first plan's
    and the last cycle's left out."""
    first_times: list[float] = field(default_factory=list)
    iteration_times: list[np.ndarray] = field(default_factory=list)
    """Per problem, the wall time per Newton iteration (s) of its cycles after the first plan that iterated."""
    flagged: int = 0
    cycles: int = 0
    problems: list[int] = field(default_factory=list)
    """The workspace set's numbers of the problems."""
    budget: float | None = None
    """The wall budget per cycle (s), for the budgeted loops."""


def jumped_goal(planner: comanip.Planner, problem, size: float, rng: np.random.Generator) -> np.ndarray:
    """The problem's goal moved by ``size`` (m) in a random direction; for an arm, one it reaches from the start."""
    model = planner.model
    for _ in range(100):
        direction = rng.normal(size=model.d)
        goal = problem.goal + size * direction / np.linalg.norm(direction)
        reach = ReachParameters(problem.start, goal, problem.width)
        goal_q = planner.goal_joints(reach)
        if goal_q is None or planner.reaches(goal_q, reach):
            return goal
    raise RuntimeError(f"no reachable goal {size} m from {problem.goal}")


def run_preset(preset: str, count: int, rate: float | None, budget: float | None, progress) -> tuple[str, dict[tuple[str, bool], LoopRuns]]:
    """The preset's kind of body ('arm' or 'point mass') and every loop's runs on its problems, with and without
    motor noise, keyed by (loop, noise)."""
    model = comanip.presets.load(preset)
    planner = comanip.Planner(model, SolverOptions(compile=True))  # a long-lived point-mass planner's compiled terms
    kind = planner.kind.name
    budget = BUDGETS[kind] if budget is None else budget
    problems = workspace.load(preset)
    chosen = np.unique(np.linspace(0, len(problems) - 1, count).round().astype(int))
    period = model.h if rate is None else 1.0 / rate
    steps = round(RUN_LENGTH * model.H * model.h / period)
    loops = {"converged": Replanner(planner, iterations=None), "1 iteration": Replanner(planner, iterations=1),
             "budget": Replanner(planner, iterations=None, max_wall_time=budget),
             "full solve, budget": BudgetedFullSolves(planner, budget)}
    runs = {(name, noise): LoopRuns(budget=budget if "budget" in name else None) for noise in (True, False) for name in loops}
    rng = np.random.default_rng(0)
    for number, index in enumerate(chosen):
        problem = problems[index]
        jump = [(JUMP_AT * model.H * model.h, jumped_goal(planner, problem, JUMPS[number % 2], rng))]
        for (name, noise), record in runs.items():
            run = execute_receding_horizon(loops[name], problem.start, problem.goal, problem.width, steps=steps,
                                           rng=np.random.default_rng(int(index)), noise=noise, period=period,
                                           observation=EXACT_STATE, goal_jumps=jump)
            record.costs.append(executed_cost(planner, run, problem.width))
            record.scales.append(planner.problem.normaliser(problem.width))
            record.successes.append(bool(np.linalg.norm(run.ee[-1] - run.goals[-1]) <= problem.width))
            record.final_hands.append(run.ee[-1])
            record.cycle_times.append(run.replan_times[1:])
            # the code before the preparation phase records none
            prepared = getattr(run, "preparation_times", None)
            record.preparation_times.append(np.zeros(steps - 2) if prepared is None else prepared[1:-1])
            record.first_times.append(float(run.replan_times[0]))
            iterated = run.replan_iterations[1:] > 0
            record.iteration_times.append(run.replan_times[1:][iterated] / run.replan_iterations[1:][iterated])
            record.flagged += sum(status == Progress.NOT_CONTRACTING for status in run.replan_statuses[1:])
            record.cycles += steps - 1
            record.problems.append(int(index))
        progress(f"{preset} problem {number + 1}/{len(chosen)} (#{index}, {problem.describe()})")
    return kind, runs


def summary(runs: dict[tuple[str, bool], LoopRuns]) -> dict[tuple[str, bool], dict]:
    """Per loop and noise: costs relative to the converged loop's with the same noise, successes, cycle-time
    statistics (ms) and the slowest cycles."""
    out = {}
    for (name, noise), record in runs.items():
        reference = np.array(runs["converged", noise].costs)
        apart = np.linalg.norm(np.array(record.final_hands) - np.array(runs["converged", noise].final_hands), axis=1)
        relative = (np.array(record.costs) - reference) / np.array(record.scales)
        times, per_iteration = np.concatenate(record.cycle_times), np.concatenate(record.iteration_times)
        preparations = np.concatenate(record.preparation_times)
        with_preparation = np.concatenate([t[:-1] + p for t, p in zip(record.cycle_times, record.preparation_times)])
        slowest = sorted(((t, problem, cycle + 1) for problem, cycle_times in zip(record.problems, record.cycle_times)
                          for cycle, t in enumerate(cycle_times)), reverse=True)[:SLOWEST]
        out[name, noise] = {"total": float(relative.mean()),
                            "largest": float(relative.max()), "successes": sum(record.successes), "problems": len(relative),
                            "final_apart_mm": 1e3 * float(apart.max()),
                            "median_ms": 1e3 * float(np.median(times)), "p99_ms": 1e3 * float(np.percentile(times, 99)),
                            "largest_ms": 1e3 * float(times.max()), "first_ms": 1e3 * float(np.median(record.first_times)),
                            "preparation_ms": 1e3 * float(np.median(preparations)),
                            "preparation_p99_ms": 1e3 * float(np.percentile(preparations, 99)),
                            "with_preparation_p99_ms": 1e3 * float(np.percentile(with_preparation, 99)),
                            "iteration_ms": 1e3 * float(np.median(per_iteration)) if len(per_iteration) else None,
                            "flagged": record.flagged / record.cycles, "cycles": record.cycles,
                            "slowest": [(1e3 * t, p, c) for t, p, c in slowest], "budget": record.budget}
    return out


def per_iteration_text(milliseconds: float | None) -> str:
    """The time per iteration for the table: a dash for a loop none of whose cycles iterated."""
    return "–" if milliseconds is None else f"{milliseconds:.2f} ms"


def loop_label(key: tuple[str, bool], row: dict) -> str:
    name, noise = key
    name = f"{name} ({1e3 * row['budget']:g} ms)" if row["budget"] is not None else name
    return f"{name}, {'motor noise' if noise else 'no noise'}"


def markdown(results: dict[str, dict], kinds: dict[str, str], args) -> str:
    cycle = "loops at each preset's own step h" if args.rate == "step" else f"{float(args.rate):g} Hz loops"
    lines = [f"Measured by `benchmarks/realtime_loops.py --markdown --presets {args.presets} --problems {args.problems} "
             f"--rate {args.rate}` ({cycle} of 1.5 H·h, each problem's goal jumping by 5 or 20 cm at "
             f"0.3 H·h; executed cost minus the converged loop's with the same noise, over |J_best|, the mean over the "
             f"problems and the largest; cycle times after the first plan, from the state to tau_0, and the preparation of "
             f"the next cycle after tau_0; 1-minute load average "
             f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores at the end):", "",
             "| preset | loop | executed cost vs converged (of \\|J_best\\|), mean / largest | reached | hand's end from the converged loop's, largest | cycle median | p99 | largest | per iteration, median | preparation after tau_0, median / p99 | cycle and preparation, p99 | first plan (cold), median | flagged 'not_contracting' |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for preset, rows in results.items():
        for key, row in rows.items():
            lines.append(f"| {preset} | {loop_label(key, row)} | {100 * row['total']:+.3f} % / {100 * row['largest']:+.3f} % "
                         f"| {row['successes']}/{row['problems']} | {row['final_apart_mm']:.1f} mm | {row['median_ms']:.2f} ms | {row['p99_ms']:.2f} ms "
                         f"| {row['largest_ms']:.1f} ms | {per_iteration_text(row['iteration_ms'])} "
                         f"| {row['preparation_ms']:.2f} / {row['preparation_p99_ms']:.2f} ms | {row['with_preparation_p99_ms']:.2f} ms "
                         f"| {row['first_ms']:.1f} ms | {100 * row['flagged']:.1f} % |")
    lines += ["", f"Targets: every cycle within the budget at p99 ({', '.join(f'{1e3 * b:g} ms for {PLURALS[k]}' for k, b in BUDGETS.items())}), "
              f"the executed cost with motor noise no more than {100 * COST_TARGET:g} % of |J_best| above the converged loop's, as many "
              f"reaches; without noise, on every problem, the cost no more than {100 * WORST_COST_TARGET:g} % above it and the hand "
              f"ending within {1e3 * FINAL_HAND_TARGET:g} mm of where the converged loop's ends:", ""]
    for preset, rows in results.items():
        target = BUDGETS[kinds[preset]]
        for name in REAL_TIME_LOOPS:
            row, converged = rows[name, True], rows["converged", True]
            misses = [f"p99 {row['p99_ms']:.2f} ms > {1e3 * target:g} ms" for _ in [0] if row["p99_ms"] > 1e3 * target] + \
                [f"cost {100 * row['total']:+.3f} %" for _ in [0] if row["total"] > COST_TARGET] + \
                [f"{row['successes']} reached against {converged['successes']}" for _ in [0]
                 if row["successes"] < converged["successes"]]
            exact = rows[name, False]
            misses += [f"without noise, cost {100 * exact['largest']:+.3f} % on the worst problem" for _ in [0]
                       if exact["largest"] > WORST_COST_TARGET] + \
                [f"without noise, the hand {exact['final_apart_mm']:.1f} mm from the converged loop's" for _ in [0]
                 if exact["final_apart_mm"] > 1e3 * FINAL_HAND_TARGET]
            lines.append(f"- {preset}, {loop_label((name, True), row).removesuffix(', motor noise')}: "
                         + ("met" if not misses else "missed: " + "; ".join(misses)))
    lines += ["", f"The {SLOWEST} slowest cycles of each loop (ms, workspace problem #, cycle):", ""]
    for preset, rows in results.items():
        for key, row in rows.items():
            slow = "; ".join(f"{t:.1f} ms (#{p}, cycle {c})" for t, p, c in row["slowest"])
            lines.append(f"- {preset}, {loop_label(key, row)}: {slow}")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--presets", default="franka_rest,planar,cartesian,human,human_cartesian")
    parser.add_argument("--problems", type=int, default=20, help="problems per preset, spread over its workspace set")
    parser.add_argument("--rate", default="100", help="control rate (Hz), or 'step': each preset's own step h")
    parser.add_argument("--budget", type=float, default=None, help="wall budget per cycle (s); default 5 ms arms, 1 ms point masses")
    parser.add_argument("--markdown", action="store_true", help="print the speed page's block")
    parser.add_argument("--compare", default=None, help="another checkout (its folder) or a git revision: the same loops "
                        "with its code, in a process of its own beside this one, its table after this one's")
    args = parser.parse_args(argv)
    rate = None if args.rate == "step" else float(args.rate)
    previous = None
    if args.compare is not None:
        reference, clean_up = reference_source(args.compare)
        command = [sys.executable, __file__, "--presets", args.presets, "--problems", str(args.problems), "--rate", args.rate,
                   *(["--budget", str(args.budget)] if args.budget is not None else []), "--markdown"]
        previous = subprocess.Popen(command, stdout=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(reference)})
    results, kinds = {}, {}
    for preset in args.presets.split(","):
        kinds[preset], runs = run_preset(preset, args.problems, rate, args.budget,
                                         lambda text: print(text, file=sys.stderr, flush=True))
        results[preset] = summary(runs)
        for key, row in results[preset].items():  # with --markdown on stderr, as progress
            print(f"{preset:16s} {loop_label(key, row):44s} cost {100 * row['total']:+.3f} % (largest "
                  f"{100 * row['largest']:+.3f} %) reached {row['successes']}/{row['problems']} cycles "
                  f"{row['median_ms']:.2f} / {row['p99_ms']:.2f} / {row['largest_ms']:.1f} ms flagged "
                  f"{100 * row['flagged']:.1f} %", file=sys.stderr if args.markdown else sys.stdout, flush=True)
    if args.markdown:
        print(markdown(results, kinds, args))
    if previous is not None:
        table = previous.communicate()[0]
        clean_up()
        print(f"\nThe same loops with the code of {args.compare}, run beside these in a process of its own:\n\n{table}")


if __name__ == "__main__":
    main()
