"""Leaving out an arm's worst cold guess: would the minimum-jerk start of highest objective, left out of a cold
search for goals beyond T widths, have ended best?

    PYTHONPATH=src .venv/bin/python -m studies.may_an_arm_cold_search_leave_out_its_worst_guess.measure_left_out_guess [--preset franka] [--problems 200] [--seed 0] [--ratios 0,2,3,4,6,8]
    PYTHONPATH=src .venv/bin/python -m studies.may_an_arm_cold_search_leave_out_its_worst_guess.measure_left_out_guess --summarise left_out_franka_seed0.csv

On cold_quality.py's random cold problems of an arm (from the ready pose, every tenth start moving; goals 0.15–0.3 m
away, widths 2.5–10 cm), each minimum-jerk start is solved to the end in stages, its objective read at the planner's
``abandon_after`` checkpoint (the start scoring of studies/may_an_arm_cold_search_abandon_long_starts/). For each
ratio T the search the planner runs with ``SolverOptions(arm_narrow_ratio=T)`` (from rest, for a goal beyond T widths
from the hand, the start of highest objective left out; the rest abandoned at the checkpoint as the planner does) is scored
against the full search (every start to the end, ``cold_search="all"``): the share of problems within 1e-4 of the
full search's objective, the largest relative excess, successes, the share of problems that leave a start out, and
the minimum-jerk durations left out (shortest / middle / longest), the iterations of the longest start kept (the
wall time of starts solved side by side follows it), median and p90, with the cold-search rule's verdict
(cold_quality.py). Also: on how many problems the start of highest objective alone would have ended best (by more
than 1e-4), how far their goals are and whether they start moving. Writes every start's row to
``left_out_<preset>_seed<seed>.csv`` beside this script; ``--summarise CSV`` prints the tables of such a file again.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

import comanip  # noqa: E402
from benchmarks.cold_quality import RULE_CLOSE, RULE_SHARE, RULE_WORST, arm_problems, write_rows  # noqa: E402
from comanip.planning.planner import SolverOptions  # noqa: E402
from comanip.planning.reach_parameters import ReachParameters  # noqa: E402
from studies.may_an_arm_cold_search_abandon_long_starts.measure_abandoned_starts import abandoning, staged_starts  # noqa: E402


def scored(starts: list[dict], leave_out: bool, checkpoint: int) -> tuple[dict, int]:
    """The start a search keeps (``leave_out``: without the start of highest objective) and the iterations of its
    longest start kept."""
    kept = sorted(starts, key=lambda s: s["initial"])[:-1] if leave_out else starts
    plan, spent = abandoning(kept, checkpoint)
    return plan, max(spent)


def summarise(problems: list[list[dict]], checkpoint: int, ratios: list[float], title: str) -> None:
    """The tables of the module docstring for every start's row (``problems``: per problem, its starts)."""
    full = [min(starts, key=lambda s: (s["violated"], s["fun"])) for starts in problems]
    full_ok = sum(best["success"] for best in full)
    left_out = [max(starts, key=lambda s: s["initial"]) for starts in problems]
    best_alone = [s for s, starts in zip(left_out, problems) if s["fun"] < min(o["fun"] for o in starts if o is not s)
                  - RULE_CLOSE * abs(s["fun"])]
    at = ", ".join(f"{s['distance_over_width']:.1f}" + (" (moving)" if s["moving"] else "") for s in best_alone) or "-"
    print(f"{title}, starts abandoned after {checkpoint} iterations: from rest, the start of highest objective left "
          f"out beyond T widths, against the full search")
    print(f"the start of highest objective alone ends best (by > {RULE_CLOSE:g}) on {len(best_alone)} problems, at {at} widths")
    print(f"{'T':>5} {'left out':>9} {'durations left out':>19} {'within ' + format(RULE_CLOSE, 'g'):>13} "
          f"{'largest excess':>15} {'successes':>10} {'longest start median':>21} {'p90':>6} {'rule':>8}")
    for ratio in ratios:
        leave = [starts[0]["distance_over_width"] > ratio and not starts[0]["moving"] for starts in problems]
        kept = [scored(starts, out, checkpoint) for starts, out in zip(problems, leave)]
        excess = np.array([(plan["fun"] - best["fun"]) / abs(best["fun"]) for (plan, _), best in zip(kept, full)])
        longest = np.array([n for _, n in kept])
        ok = sum(plan["success"] for plan, _ in kept)
        close, worst = float(np.mean(excess <= RULE_CLOSE)), float(excess.max())
        met = close >= RULE_SHARE and worst <= RULE_WORST and ok >= full_ok
        durations = np.bincount([s["duration_index"] for s, out in zip(left_out, leave) if out], minlength=len(problems[0]))
        print(f"{ratio:>5g} {np.mean(leave):>9.0%} {' / '.join(map(str, durations)):>19} {close:>13.1%} "
              f"{worst:>15.2e} {ok:>4}/{full_ok:<5} {np.median(longest):>21.0f} {np.percentile(longest, 90):>6.0f} "
              f"{'met' if met else 'NOT met':>8}")


def read_rows(path: Path) -> list[list[dict]]:
    """Per problem, its starts' rows, from a CSV :func:`main` wrote."""
    problems: dict[int, list[dict]] = {}
    with open(path) as file:
        for row in csv.DictReader(file):
            parsed = {key: (value == "True" if value in ("True", "False") else float(value)) for key, value in row.items()}
            parsed["duration_index"] = int(parsed["duration_index"])
            problems.setdefault(int(parsed["problem"]), []).append(parsed)
    return list(problems.values())


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="franka")
    parser.add_argument("--problems", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--ratios", default="0,2,3,4,6,8", help="comma-separated goal distances over width T")
    parser.add_argument("--summarise", type=Path, default=None, help="print the tables of a CSV written before, solve nothing")
    args = parser.parse_args(argv)
    ratios = [float(r) for r in args.ratios.split(",")]
    checkpoint = SolverOptions().abandon_after
    if args.summarise is not None:
        summarise(read_rows(args.summarise), checkpoint, ratios, args.summarise.name)
        return
    model = comanip.presets.load(args.preset)
    planner = comanip.Planner(model, SolverOptions(cold_search="all", threads=1))
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    problems, rows, begin = [], [], time.perf_counter()
    for index, (start, goal, width) in enumerate(arm_problems(model, args.problems, seed=args.seed)):
        params = ReachParameters(start, goal, width)
        starts = staged_starts(planner, params, [checkpoint])
        for duration, (s, guess) in enumerate(zip(starts, planner.starts.searched_guesses(params))):
            s.update(initial=planner.starts.objective(guess, params), duration_index=duration,
                     distance_over_width=float(np.linalg.norm(goal - hand) / width), moving=bool(np.any(start[model.n:])))
        problems.append(starts)
        rows += [{"problem": index, **s} for s in starts]
        if (index + 1) % 20 == 0:
            print(f"  {index + 1}/{args.problems} problems, {time.perf_counter() - begin:.0f} s", file=sys.stderr, flush=True)
    write_rows(HERE / f"left_out_{args.preset}_seed{args.seed}.csv", rows)
    summarise(problems, checkpoint, ratios, f"{args.preset}, {len(problems)} cold problems (seed {args.seed})")


if __name__ == "__main__":
    main()
