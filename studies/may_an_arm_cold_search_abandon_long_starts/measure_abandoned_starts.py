"""Abandoning a cold search's long starts: would a start still running after K Newton iterations, beaten by then
by a start that has converged, have ended best?

    PYTHONPATH=src .venv/bin/python -m studies.may_an_arm_cold_search_abandon_long_starts.measure_abandoned_starts [--preset franka] [--problems 100] [--checkpoints 60,80,100,150]

On cold_quality.py's random cold problems of an arm (from the ready pose, every tenth start moving), each
minimum-jerk start is solved to the end in stages (``NewtonSolve.advance``), its objective read at every checkpoint
K. For each K, the search that abandons there (``SolverOptions(abandon_after=K)``: a start not converged after K
iterations is dropped when a start that converged within the limits by then has a lower objective) is scored
against the full search (every start to the end, ``cold_search="all"``): how often its plan is within 1e-4 of the
full search's objective, its largest relative excess, successes, and the iterations it spends (summed over the
starts, median and p90) against the full search's; with the cold-search rule's verdict (cold_quality.py:
RULE_CLOSE, RULE_SHARE, RULE_WORST). Writes every start's row to studies/may_an_arm_cold_search_abandon_long_starts/franka_abandon.csv.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np


import comanip  # noqa: E402
from benchmarks.cold_quality import RULE_CLOSE, RULE_SHARE, RULE_WORST, arm_problems, write_rows  # noqa: E402
from comanip.optim import CONVERGED  # noqa: E402
from comanip.planning.path_limits import LIMIT_TOLERANCE  # noqa: E402
from comanip.planning.planner import SolverOptions  # noqa: E402
from comanip.planning.reach_parameters import ReachParameters  # noqa: E402


def staged_starts(planner, params, checkpoints: list[int]) -> list[dict]:
    """Each minimum-jerk start solved to the end, with (objective, converged within the limits) at each checkpoint."""
    rows = []
    for guess in planner.starts.searched_guesses(params):
        solve = planner.solver.newton_solve(guess, params, np.inf, planner.curvature)
        row = {}
        for k in checkpoints:
            result = solve.advance(k)
            row[f"fun_{k}"] = result.fun
            row[f"converged_{k}"] = solve.finished and result.status in CONVERGED and result.violation <= LIMIT_TOLERANCE
        result = solve.advance(planner.solver.max_iterations)
        row.update(fun=result.fun, iterations=result.nit, success=result.success, violated=result.violation > LIMIT_TOLERANCE)
        rows.append(row)
    return rows


def abandoning(starts: list[dict], k: int) -> tuple[dict, list[int]]:
    """The start the search abandoning at checkpoint k keeps (the planner's rule), and the iterations each start
    spends."""
    lowest = min((s[f"fun_{k}"] for s in starts if s[f"converged_{k}"]), default=np.inf)
    kept, spent = [], []
    for s in starts:
        if s["iterations"] <= k or not s[f"fun_{k}"] > lowest:
            kept.append(s)
            spent.append(s["iterations"])
        else:
            spent.append(k)
    return min(kept, key=lambda s: (s["violated"], s["fun"])), spent


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="franka")
    parser.add_argument("--problems", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--checkpoints", default="60,80,100,150", help="comma-separated iteration counts K")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "franka_abandon.csv")
    args = parser.parse_args(argv)
    checkpoints = sorted(int(k) for k in args.checkpoints.split(","))
    model = comanip.presets.load(args.preset)
    planner = comanip.Planner(model, SolverOptions(cold_search="all", threads=1))
    problems, rows, begin = [], [], time.perf_counter()
    for index, (start, goal, width) in enumerate(arm_problems(model, args.problems, seed=args.seed)):
        starts = staged_starts(planner, ReachParameters(start, goal, width), checkpoints)
        problems.append(starts)
        rows += [{"problem": index, "start": j, **s} for j, s in enumerate(starts)]
        if (index + 1) % 10 == 0:
            print(f"  {index + 1}/{args.problems} problems, {time.perf_counter() - begin:.0f} s", flush=True)
    full = [min(starts, key=lambda s: (s["violated"], s["fun"])) for starts in problems]
    full_iterations = np.array([sum(s["iterations"] for s in starts) for starts in problems])
    full_ok = sum(best["success"] for best in full)
    print(f"{args.preset}, {len(problems)} cold problems (seed {args.seed}): abandoning at K against the full search "
          f"(iterations median {np.median(full_iterations):.0f}, p90 {np.percentile(full_iterations, 90):.0f})")
    print(f"{'K':>5} {'within ' + format(RULE_CLOSE, 'g'):>13} {'largest excess':>15} {'successes':>10} "
          f"{'iterations median':>18} {'p90':>6} {'rule':>8}")
    for k in checkpoints:
        kept = [abandoning(starts, k) for starts in problems]
        excess = np.array([(plan["fun"] - best["fun"]) / abs(best["fun"]) for (plan, _), best in zip(kept, full)])
        spent = np.array([sum(spent) for _, spent in kept])
        ok = sum(plan["success"] for plan, _ in kept)
        close, worst = float(np.mean(excess <= RULE_CLOSE)), float(excess.max())
        met = close >= RULE_SHARE and worst <= RULE_WORST and ok >= full_ok
        print(f"{k:>5} {close:>13.1%} {worst:>15.2e} {ok:>4}/{full_ok:<5} {np.median(spent):>18.0f} "
              f"{np.percentile(spent, 90):>6.0f} {'met' if met else 'NOT met':>8}")
    write_rows(args.out, rows)


if __name__ == "__main__":
    main()
