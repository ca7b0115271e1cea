"""Racing the minimum-jerk starts of an arm's cold solve: would a few Newton iterations from each start pick the
start the full search would have kept?

    PYTHONPATH=src .venv/bin/python -m studies.does_racing_the_arm_cold_starts_keep_the_best.measure_racing [--preset franka] [--problems 200] [--budgets 2,3,5,8]

On cold_quality.py's random cold problems of an arm (from the ready pose, every tenth start moving), each
minimum-jerk start is solved to convergence (the full search, ``cold_search="all"``, keeps the best) and, for
each budget k, for k iterations only. Racing with budget k keeps the start whose k-iteration iterate ranks best
(within the limits first, then the lower objective) and finishes that solve alone: its plan is that start's full
solve, so its quality is read off the full solves. Prints per budget how often racing keeps a plan within 1e-4
of the full search's objective, its largest relative excess, and whether the cold-search rule holds
(cold_quality.py: RULE_CLOSE, RULE_SHARE, RULE_WORST); with the iterations racing would spend against the full
search's. Writes every problem's row to studies/does_racing_the_arm_cold_starts_keep_the_best/franka_racing.csv.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np


import comanip  # noqa: E402
from benchmarks.cold_quality import RULE_CLOSE, RULE_SHARE, RULE_WORST, arm_problems, write_rows  # noqa: E402
from comanip.optim import Status  # noqa: E402
from comanip.planning.planner import SolverOptions  # noqa: E402
from comanip.planning.reach_parameters import ReachParameters  # noqa: E402


def rank(result) -> tuple[bool, float]:
    """The planner's order of results: within the limits first, then the lower normalised objective."""
    return result.status == Status.CONSTRAINTS_VIOLATED or result.violation > 1e-6, result.fun


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="franka")
    parser.add_argument("--problems", type=int, default=200)
    parser.add_argument("--budgets", default="2,3,5,8", help="comma-separated iteration budgets of the race")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "franka_racing.csv")
    args = parser.parse_args(argv)
    budgets = [int(b) for b in args.budgets.split(",")]
    model = comanip.presets.load(args.preset)
    full = comanip.Planner(model, SolverOptions(cold_search="all"))
    short = {k: comanip.Planner(model, SolverOptions(cold_search="all", max_iterations=k)) for k in budgets}
    rows, begin = [], time.perf_counter()
    for index, (start, goal, width) in enumerate(arm_problems(model, args.problems)):
        params = ReachParameters(start, goal, width)
        guesses = full.starts.searched_guesses(params)
        finished = [full.solver.solve(guess, params) for guess in guesses]
        best = min(range(len(guesses)), key=lambda j: rank(finished[j]))
        row = {"problem": index, "moving": bool(np.any(start[model.n:])), "full_objective": finished[best].fun,
               "full_iterations": sum(r.nit for r in finished), "full_success": finished[best].success}
        for k in budgets:
            raced = [short[k].solver.solve(guess, params) for guess in guesses]
            kept = min(range(len(guesses)), key=lambda j: rank(raced[j]))
            row[f"race{k}_relative"] = (finished[kept].fun - finished[best].fun) / abs(finished[best].fun)
            row[f"race{k}_iterations"] = sum(r.nit for r in raced) + finished[kept].nit - raced[kept].nit
            row[f"race{k}_success"] = finished[kept].success
        rows.append(row)
        if (index + 1) % 20 == 0:
            print(f"  {index + 1}/{args.problems} problems, {time.perf_counter() - begin:.0f} s", flush=True)
    print(f"{args.preset}, {len(rows)} cold problems: racing the {len(guesses)} minimum-jerk starts against the full search")
    print(f"{'budget':>7} {'within ' + format(RULE_CLOSE, 'g'):>13} {'largest excess':>15} {'successes':>10} "
          f"{'iterations (median)':>20} {'rule':>8}")
    full_ok = sum(r["full_success"] for r in rows)
    for k in budgets:
        relative = np.array([r[f"race{k}_relative"] for r in rows])
        ok = sum(r[f"race{k}_success"] for r in rows)
        close, worst = float(np.mean(relative <= RULE_CLOSE)), float(relative.max())
        met = close >= RULE_SHARE and worst <= RULE_WORST and ok >= full_ok
        print(f"{k:>7} {close:>13.1%} {worst:>15.2e} {ok:>4}/{full_ok:<5} "
              f"{np.median([r[f'race{k}_iterations'] for r in rows]):>9.0f} of {np.median([r['full_iterations'] for r in rows]):<8.0f}"
              f" {'met' if met else 'NOT met':>8}")
    write_rows(args.out, rows)


if __name__ == "__main__":
    main()
