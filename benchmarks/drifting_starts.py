"""Cold solves from moving starts that carry the hand on: where their Newton iterations go, and which starts a
cheaper search would need to match the full one.

    .venv/bin/python benchmarks/drifting_starts.py [--presets planar,cartesian] [--problems 200] [--workspace]

A point mass's 'ranked' cold solve from a start whose motion carries the hand on past ``narrow_ratio`` widths
(:meth:`StartPolicy.carried_on <comanip.planning.starts.StartPolicy.carried_on>`) runs every minimum-jerk guess;
every other cold solve runs one start. On cold_quality.py's problems (``--workspace``: the preset's sampled
workspace set), prints per preset the Newton iterations of the planner's cold solves from moving starts, those
carried on apart from the others, and, on the problems carried on, what each cheaper choice of starts would end
with against the full search ('all guesses'): the lowest-objective minimum-jerk guess alone, the two of lowest
objective, and the lowest-objective guess with the lowest-objective stopped reach
(:meth:`StartPolicy.stopped_reaches <comanip.planning.starts.StartPolicy.stopped_reaches>` on every local optimum
of the reach library). Each start is solved as the planner solves it (one BLAS thread: the iterates of a long
solve depend on the BLAS's rounding, and so, now and then, does the local optimum it ends on). Columns: the
iterations (median / p90 / largest), the share of problems within 1e-4 relative of the full search's objective
and the largest relative excess: the cold-search rule of cold_quality.py asks ≥ 98 % within 1e-4 and no excess
beyond 1e-3.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import comanip
from comanip.planning.reach_parameters import ReachParameters

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cold_quality import problems, workspace_problems  # noqa: E402

STRATEGIES = ("all guesses", "lowest-objective guess", "two lowest-objective guesses",
              "lowest-objective guess + stopped reach")


def chosen_results(planner, params: ReachParameters) -> dict[str, list]:
    """The solver results (each start solved alone, as the planner solves it) of each strategy's starts."""
    starts, solver = planner.starts, planner.solver
    guesses = starts.cold_guesses(params, planner.options.n_starts)
    order = np.argsort([starts.objective(guess, params) for guess in guesses])
    solved = solver.results(guesses, params)
    motion = params.start.copy()
    motion[: planner.model.n] = 0.0
    for reach in starts.stopped_starts(params, starts.stops(motion)):
        starts.library.fill(reach, bracket=True)
    stopped = solver.results([starts.lowest_objective(starts.stopped_reaches(params, motion, every_optimum=True), params)], params)
    return dict(zip(STRATEGIES, ([solved[k] for k in order], [solved[order[0]]], [solved[k] for k in order[:2]],
                                 [solved[order[0]]] + stopped)))


def spread(values) -> str:
    """'median / p90 / largest' of iteration counts."""
    values = np.asarray(values)
    return f"{np.median(values):.0f} / {np.percentile(values, 90):.0f} / {values.max()}" if values.size else "–"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--presets", default="planar,cartesian")
    parser.add_argument("--problems", type=int, default=200)
    parser.add_argument("--workspace", action="store_true", help="the sampled workspace sets' problems")
    args = parser.parse_args(argv)
    print("| preset | moving starts | carried on | ranked cold solve, iterations: carried on | others moving "
          "| choice of starts (carried on) | iterations | within 1e-4 | largest excess |")
    print("|---|---|---|---|---|---|---|---|---|")
    for preset in args.presets.split(","):
        model = comanip.presets.load(preset)
        planner = comanip.Planner(model)
        cases = workspace_problems(preset, args.problems) if args.workspace else problems(model, args.problems)
        iterations = {True: [], False: []}
        outcomes = {strategy: [] for strategy in STRATEGIES}
        for start, goal, width in cases:
            params = ReachParameters(model.full_state(start), goal, width)
            if not params.start[model.n:].any():
                continue
            carried_on = planner.starts.carried_on(params)
            iterations[carried_on].append(planner.solve(start, goal, width).iterations)
            if carried_on:
                results = chosen_results(planner, params)
                full = min(result.fun for result in results["all guesses"])
                for strategy, chosen in results.items():
                    outcomes[strategy].append(((min(r.fun for r in chosen) - full) / abs(full), sum(r.nit for r in chosen)))
        moving = len(iterations[True]) + len(iterations[False])
        head = f"| {preset} | {moving} | {len(iterations[True])} | {spread(iterations[True])} | {spread(iterations[False])} "
        if not iterations[True]:
            print(head + "| – | – | – | – |", flush=True)
            continue
        for strategy, rows in outcomes.items():
            excess = np.array([row[0] for row in rows])
            print(head + f"| {strategy} | {spread([row[1] for row in rows])} | {np.mean(excess <= 1e-4):.1%} "
                  f"| {max(excess.max(), 0.0):.1e} |", flush=True)
            head = "| | | | | "


if __name__ == "__main__":
    main()
