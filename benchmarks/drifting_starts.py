"""Cold solves from drifting starts: which starts would a cheaper search need to match the full one?

(The planner ran the full search from such starts until the cold-search rule of benchmarks/cold_quality.py let
it start from the ranked starts as from any other.)

    .venv/bin/python benchmarks/drifting_starts.py [--preset cartesian] [--problems 200]

On the moving starts of cold_quality.py's problems whose own motion would carry the hand past the goal (the
planner then solves from every minimum-jerk guess), solves from each of six starts: the three minimum-jerk
guesses and the preset's solved reach turned to the goal with the three braking moves superposed. Prints, per
problem, each strategy's J above the best of the six (relative) and the Newton iterations of each start, then
how often each strategy ends more than 1e-6 above the full search ('all guesses') and the iterations it takes:
'best guess + best library' solves from the lowest-objective guess and the lowest-objective library start only.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import comanip
from comanip.planning.starts.initial_guess import guess_durations, minimum_jerk_torques
from comanip.planning.planner import SolverOptions
from comanip.planning.reach_parameters import ReachParameters

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cold_quality import problems  # noqa: E402


def drift(planner, params: ReachParameters) -> float:
    """How far (m) the start's motion alone (zero commands) carries the hand within the horizon."""
    model = planner.model
    free = planner.problem.trajectory(tau=np.zeros(model.H * model.n), s0=params.start, goal=params.goal, width=params.width)
    return float(np.max(np.linalg.norm(np.asarray(free["ee_mean"]).T - free["ee_mean"][:, 0].full().T, axis=1)))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--preset", default="cartesian")
    parser.add_argument("--problems", type=int, default=200)
    args = parser.parse_args(argv)
    model = comanip.presets.load(args.preset)
    planner = comanip.Planner(model, SolverOptions(compile=True))
    n, durations = model.n, guess_durations(model.duration, 3)
    worse_than_full = {"best guess + best library": 0, "lowest-objective start": 0}
    iterations = {"all guesses": 0, "best guess + best library": 0}
    count = 0
    for k, (start, goal, width) in enumerate(problems(model, args.problems)):
        params = ReachParameters(start, goal, width)
        if not start[n:].any() or drift(planner, params) <= np.linalg.norm(goal - start[:n]):
            continue
        count += 1
        motion = start.copy()
        motion[:n] = 0.0
        turned = planner.starts.library.guess(start, goal, width)
        starts = planner.starts.cold_guesses(params, 3) + list(
            turned + minimum_jerk_torques(model.body, model.h, model.H, motion, np.zeros(n), durations, planner.starts.linear_dynamics))
        ranks = np.array([planner.starts.objective(s, params) for s in starts])
        results = [planner.solver.solve(s, params) for s in starts]
        J = np.array([r.fun for r in results])
        its = [r.nit for r in results]
        guess, library = int(np.argmin(ranks[:3])), 3 + int(np.argmin(ranks[3:]))
        full, pair, lowest = J[:3].min(), min(J[guess], J[library]), J[int(np.argmin(ranks))]
        scale = abs(J.min())
        worse_than_full["best guess + best library"] += (pair - full) / scale > 1e-6
        worse_than_full["lowest-objective start"] += (lowest - full) / scale > 1e-6
        iterations["all guesses"] += sum(its[:3])
        iterations["best guess + best library"] += its[guess] + its[library]
        print(f"problem {k}: above the best of six: all guesses {(full - J.min()) / scale:.1e}, "
              f"best guess + best library {(pair - J.min()) / scale:.1e}, lowest-objective start "
              f"{(lowest - J.min()) / scale:.1e}; iterations per start {its}", flush=True)
    print(f"{count} drifting starts; ends more than 1e-6 above the full search: {worse_than_full}; "
          f"iterations in all: {iterations}")


if __name__ == "__main__":
    main()
