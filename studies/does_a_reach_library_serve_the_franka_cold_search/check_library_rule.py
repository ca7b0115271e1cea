"""Would a reach library for the paper's `franka` preset pass the cold-solve quality rule?

    comanip library --preset franka --out /tmp/reach_library_franka.npz                       # ~3 min here
    PYTHONPATH=src .venv/bin/python benchmarks/cold_quality.py --presets franka --problems 200   # the full search
    PYTHONPATH=src .venv/bin/python -m studies.does_a_reach_library_serve_the_franka_cold_search.check_library_rule /tmp/reach_library_franka.npz \\
        benchmarks/results/cold_quality.csv [--strategy library|library+guess]

The rule for cold solves: on ≥ 200 random cold problems (a tenth from moving starts; :func:`cold_quality.arm_problems`),
the cold result's objective is within 1e-4 relative of the full search's (``cold_search="all"``, the reference
column of the CSV ``cold_quality.py`` writes without ``--compare``) in at least 98 % of problems, never more than
1e-3 worse, and its success rate is not lower.

Strategies, each with the library passed as ``SolverOptions(arm_library=...)``:

- ``library``: the planner's cold start from the library (the lowest-objective start among the library's nearest
  plans and the minimum-jerk guesses, the guesses solved only if that start does not converge);
- ``library+guess``: that start and the lowest-objective minimum-jerk guess both solved (the same guess twice when
  it was the start), the better plan kept.

Prints the counts the rule reads, successes and the median and p90 solve times.
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import numpy as np


import comanip  # noqa: E402
from benchmarks.cold_quality import arm_problems  # noqa: E402
from comanip.planning.planner import Planner, SolverOptions  # noqa: E402
from comanip.planning.starts import StartPolicy  # noqa: E402


class LibraryAndGuessStarts(StartPolicy):
    """The ``library+guess`` strategy: the library's start and the best minimum-jerk guess."""

    def arm_library_starts(self, params, goal_q=None):
        best, *guesses = super().arm_library_starts(params, goal_q)
        return [best, self.lowest_objective(guesses, params)]


class LibraryAndGuess(Planner):
    """The planner with the ``library+guess`` strategy, running every start it is given."""

    def _build(self):
        super()._build()
        self.starts.__class__ = LibraryAndGuessStarts

    def _solve_from(self, guesses, params, t_begin, max_wall_time, until_converged=False):
        return super()._solve_from(guesses, params, t_begin, max_wall_time, until_converged=False)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("library", type=Path, help="the franka model's library (.npz, comanip library)")
    parser.add_argument("reference", type=Path, help="cold_quality.py's CSV for --presets franka (full-search reference)")
    parser.add_argument("--strategy", default="library", choices=("library", "library+guess"))
    args = parser.parse_args(argv)
    reference = {int(row["problem"]): row for row in csv.DictReader(open(args.reference)) if row["preset"] == "franka"}
    model = comanip.presets.load("franka")
    kind = LibraryAndGuess if args.strategy == "library+guess" else Planner
    planner = kind(model, SolverOptions(arm_library=str(args.library)))
    rest = np.r_[model.body.home_position, np.zeros(model.n)]
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    planner.solve(rest, hand + 0.2 * np.eye(model.d)[0], model.width)  # one-off work, untimed
    relative, times, successes = [], [], 0
    for k, (start, goal, width) in enumerate(arm_problems(model, len(reference))):
        plan = planner.solve(start, goal, width)
        full = float(reference[k]["ref_objective"])
        relative.append((plan.objective - full) / abs(full))
        times.append(plan.solve_time)
        successes += plan.success
    relative = np.array(relative)
    n = len(relative)
    ok_ref = sum(row["ref_success"] == "True" for row in reference.values())
    print(f"strategy {args.strategy}: {n} problems; within 1e-4 of the full search {int(np.sum(relative <= 1e-4))} "
          f"({100 * np.mean(relative <= 1e-4):.1f} %, the rule: ≥ 98 %); worse by more than 1e-3: {int(np.sum(relative > 1e-3))} "
          f"(the rule: 0; largest {relative.max():.2e}); successes {successes}/{n} against {ok_ref}/{n}; "
          f"median {1e3 * np.median(times):.0f} ms, p90 {1e3 * np.percentile(times, 90):.0f} ms")
    worst = np.argsort(-relative)[:6]
    print("most worse: " + ", ".join(f"problem {k} ({relative[k]:.2e})" for k in worst))


if __name__ == "__main__":
    main()
