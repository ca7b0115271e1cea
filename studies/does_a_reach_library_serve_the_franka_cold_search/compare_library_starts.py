"""Cold arm solves from a reach library: would a search cheaper than every minimum-jerk guess match the full one?

    .venv/bin/comanip library --preset franka --out /tmp/reach_library_franka.npz   # ~500 s, once
    .venv/bin/python -m studies.does_a_reach_library_serve_the_franka_cold_search.compare_library_starts --preset franka --library /tmp/reach_library_franka.npz [--problems 40]

On cold_quality.py's arm problems, solves from each start separately: the library start (the lowest-objective
candidate among the nearest entries' plans, their retargeted variants and the minimum-jerk guesses, as
``Planner`` picks it) and each of the three minimum-jerk guesses. Prints per problem each start's J and
Newton iterations, then per strategy (a subset of those starts, the best result kept) how often it ends more
than 1e-6 relative above the full search ('3 guesses': what a cold solve without a library runs) and its
iterations. 'library until converged' is what the planner does with a library (the guesses run only if the
library start does not end 'solved' at the goal).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import comanip
from comanip.optim import Status
from comanip.planning.starts.arm_reach_library import CANDIDATE_ENTRIES
from comanip.planning.planner import SolverOptions
from comanip.planning.reach_solver import rank as _rank
from comanip.planning.reach_parameters import ReachParameters

from benchmarks.cold_quality import RELATIVE, problems  # noqa: E402


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--preset", default="franka")
    parser.add_argument("--library", type=Path, required=True, help="the preset's library (comanip library --out)")
    parser.add_argument("--problems", type=int, default=40)
    args = parser.parse_args(argv)
    model = comanip.presets.load(args.preset)
    planner = comanip.Planner(model, SolverOptions(arm_library=str(args.library)))
    n = model.n
    strategies = {"3 guesses": [], "library until converged": [], "library + best-ranked guess": [],
                  "library + guess 0": [], "library + guess 1": [], "library + guess 2": []}
    winners = np.zeros(3, dtype=int)
    for k, (start, goal, width) in enumerate(problems(model, args.problems)):
        params = ReachParameters(start, goal, width)
        guesses = planner.starts.cold_guesses(params, planner.options.n_starts)
        library_start = planner.starts.lowest_objective(guesses + planner.starts.library_candidates(params, CANDIDATE_ENTRIES),
                                                        params)
        best_ranked = int(np.argmin([planner.starts.objective(g, params) for g in guesses]))
        library, *solved = (planner.solver.solve(s, params) for s in [library_start] + guesses)
        converged = library.status == Status.SOLVED and planner.solver.ends_at_goal(library.x, params)
        winner = min(range(3), key=lambda j: _rank(solved[j]))
        full = solved[winner]
        winners[winner] += 1
        subsets = {"3 guesses": solved, "library until converged": [library] if converged else [library] + solved,
                   "library + best-ranked guess": [library, solved[best_ranked]],
                   **{f"library + guess {j}": [library, solved[j]] for j in range(3)}}
        for name, subset in subsets.items():
            above = (min(subset, key=_rank).fun - full.fun) / abs(full.fun)
            strategies[name].append((k, above, sum(r.nit for r in subset)))
        print(f"problem {k}{' (moving)' if start[n:].any() else ''}: J library {library.fun:.9f} ({library.nit} it, "
              f"{library.status}), guesses " + ", ".join(f"{r.fun:.9f} ({r.nit} it)" for r in solved), flush=True)
    print(f"\n{args.problems} problems; the full search's best came from guess 0 / 1 / 2: {winners.tolist()}")
    print(f"{'strategy':<30} {'above':>6} {'median it':>10} {'total it':>9}  problems above (relative)")
    for name, rows in strategies.items():
        above = [(k, a) for k, a, _ in rows if a > RELATIVE]
        its = [i for _, _, i in rows]
        print(f"{name:<30} {len(above):>6} {np.median(its):>10.0f} {sum(its):>9}  "
              + ", ".join(f"{k} ({a:.1e})" for k, a in above))


if __name__ == "__main__":
    main()
