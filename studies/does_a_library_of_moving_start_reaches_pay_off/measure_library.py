"""Does a library of solved moving-start reaches pay off for the point masses' cold solves that a start's motion
carries on? How close its starts come to the full search, and whether it ever fills.

    PYTHONPATH=src python -m studies.does_a_library_of_moving_start_reaches_pay_off.measure_library \
        [--presets planar,cartesian] [--steps 0.025,0.05,0.1,0.2] [--fresh 400]

A symmetric point mass plans the same reach for every start and goal that an orthogonal map and a shift take onto
one another, and nearly the same for lengths (positions, velocities, widths) scaled together: a start moving with
velocity v towards a goal at offset D·u is, up to those maps, the start at the origin moving with
(v·u, |v - (v·u) u|) along (e_1, e_2) towards D·e_1. :class:`MovingReachLibrary` keeps such reaches on a grid of
D/w (ratio :data:`GRID_RATIO`), the width (ratio ``WIDTH_RATIO`` as the rest library), and the start velocity along
and across the goal direction in goal distances per model duration (v·T/D, step ``--steps``), each entry solved by
the full cold search on first use and keeping every distinct local optimum; a problem's candidates are the plans of
the two entries whose D/w bracket its own, turned and scaled onto it, beside the minimum-jerk guesses.

On the sampled workspace set's problems whose start carries the hand on
(:meth:`StartPolicy.carried_on <comanip.planning.starts.StartPolicy.carried_on>`), prints per preset and grid step:
the Newton iterations of the one solve from the lowest-objective candidate (median / p90 / largest; the entries'
own full searches not counted), the share within 1e-4 relative of the full search's objective and the largest
relative excess (the cold-search rule asks ≥ 98 % and ≤ 1e-3), and, after that set, the share of ``--fresh``
further random problems carried on (another seed) that still needed a new entry: a solve that needs one runs the
full search twice over before its own.
"""

from __future__ import annotations

import argparse
from typing import Callable

import numpy as np

import comanip
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.starts.reach_library import WIDTH_RATIO, distinct_optima

from benchmarks import workspace  # noqa: E402  (the workspace sets)
from benchmarks.drifting_starts import spread  # noqa: E402

GRID_RATIO = 1.15
"""Ratio of successive entries' D/w."""


def frame_onto(direction: np.ndarray, across: np.ndarray) -> np.ndarray:
    """Orthogonal (n, n) matrix taking e_1 to the unit vector ``direction`` (n,) and e_2 to the unit vector
    ``across`` (n,, orthogonal to it; zero when the start moves along the goal direction only)."""
    n = direction.size
    columns = np.column_stack([direction, across] + list(np.eye(n))) if np.any(across) else \
        np.column_stack([direction] + list(np.eye(n)))
    basis, triangle = np.linalg.qr(columns)
    return basis[:, :n] * np.where(np.diag(triangle)[:n] < 0, -1.0, 1.0)  # the first columns keep their signs


class MovingReachLibrary:
    """Reaches from moving starts of one symmetric point-mass model, solved on demand (module docstring).

    Args:
        solver: the planner's solver strategy, which solves an entry from ``starts``.
        starts: the starts (each torques (H, n)) of the full cold search for a reach's parameters.
        n: dimension of the point mass (= d).
        state_size: length of the model's state (2n plus any activation states, zero at an entry's start).
        width: w_0 (m), the width grid's anchor (the model's default).
        duration: the model's movement duration T (s), the unit of the velocity grid.
        step: the velocity grid's step (v·T/D).
    """

    def __init__(self, solver: ReachSolver, starts: Callable[[ReachParameters], list[np.ndarray]], n: int,
                 state_size: int, width: float, duration: float, step: float):
        self.solver, self.starts, self.n, self.state_size = solver, starts, n, state_size
        self.width, self.duration, self.step = float(width), float(duration), float(step)
        self._entries: dict[tuple[int, int, int, int], list[np.ndarray]] = {}

    def local_optima(self, start: np.ndarray, goal: np.ndarray, width: float, solve_missing: bool = True) -> list[np.ndarray]:
        """Every plan (H, n) of the two entries whose D/w bracket the problem's (nearest in width and velocity),
        turned and scaled onto it; empty when the goal is at the start, the start's state beyond position and velocity
        is not zero, or the entry is not solved yet and not ``solve_missing``."""
        n = self.n
        offset = np.asarray(goal, dtype=float) - start[:n]
        with np.errstate(over="ignore"):
            distance = float(np.linalg.norm(offset))
        if not 0.0 < distance < np.inf or np.any(start[2 * n:]):
            return []
        direction = offset / distance
        velocity = start[n:2 * n]
        along = float(velocity @ direction)
        perpendicular = velocity - along * direction
        across = float(np.linalg.norm(perpendicular))
        unit_across = perpendicular / across if across > 1e-12 * distance else np.zeros(n)
        scale = self.duration / distance / self.step
        ratio_index = np.log(distance / width) / np.log(GRID_RATIO)
        rest = (int(np.round(np.log(width / self.width) / np.log(WIDTH_RATIO))), int(np.round(along * scale)),
                int(np.round(across * scale)))
        frame = frame_onto(direction, unit_across)
        plans = []
        for key in sorted({(int(np.floor(ratio_index)),) + rest, (int(np.ceil(ratio_index)),) + rest}):
            if key not in self._entries:
                if not solve_missing:
                    return []
                self._entries[key] = self.solved(key)
            entry_distance = GRID_RATIO**key[0] * WIDTH_RATIO**key[1] * self.width
            plans += [(distance / entry_distance) * torque @ frame.T for torque in self._entries[key]]
        return plans

    def solved(self, key: tuple[int, int, int, int]) -> list[np.ndarray]:
        """The entry at grid point ``key`` (D/w index, width index, along and across velocity steps): the distinct
        local optima (torques (H, n), lowest objective first) of the full cold search from its start."""
        n = self.n
        entry_width = WIDTH_RATIO**key[1] * self.width
        entry_distance = GRID_RATIO**key[0] * entry_width
        start = np.zeros(self.state_size)
        start[n:n + 2] = np.array(key[2:]) * self.step * entry_distance / self.duration
        return distinct_optima(self.solver, self.starts, ReachParameters(start, entry_distance * np.eye(n)[0], entry_width))


def carried_on_problems(planner, problems) -> list[ReachParameters]:
    """The parameters of the problems whose start carries the hand on."""
    model = planner.model
    chosen = [ReachParameters(model.full_state(p.start), p.goal, p.width) for p in problems]
    return [params for params in chosen if planner.starts.carried_on(params)]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--presets", default="planar,cartesian")
    parser.add_argument("--steps", default="0.025,0.05,0.1,0.2")
    parser.add_argument("--fresh", type=int, default=400, help="further random problems (default: %(default)s)")
    args = parser.parse_args(argv)
    print("| preset | v·T/D step | carried on | iterations | within 1e-4 | largest excess | entries "
          "| fresh problems carried on | of them needing a new entry |")
    print("|---|---|---|---|---|---|---|---|---|")
    for preset in args.presets.split(","):
        model = comanip.presets.load(preset)
        planner = comanip.Planner(model)
        starts, solver = planner.starts, planner.solver
        cases = carried_on_problems(planner, workspace.load(preset))
        guesses = [starts.cold_guesses(params, planner.options.n_starts) for params in cases]
        full = [min(result.fun for result in solver.results(found, params)) for found, params in zip(guesses, cases)]
        fresh = carried_on_problems(planner, workspace.point_mass_problems(model, args.fresh, workspace.SEED + 1))
        for step in map(float, args.steps.split(",")):
            library = MovingReachLibrary(solver, lambda params: starts.cold_guesses(params, planner.options.n_starts),
                                         model.n, model.state_size, model.width, model.duration, step)
            iterations, excess = [], []
            for params, found, best in zip(cases, guesses, full):
                candidates = library.local_optima(params.start, params.goal, params.width) + found
                result = solver.results([starts.lowest_objective(candidates, params)], params)[0]
                iterations.append(result.nit)
                excess.append(max((result.fun - best) / abs(best), 0.0))
            filled = len(library._entries)
            missing = sum(not library.local_optima(params.start, params.goal, params.width, solve_missing=False)
                          for params in fresh)
            excess = np.array(excess)
            print(f"| {preset} | {step:g} | {len(cases)} | {spread(iterations)} | {np.mean(excess <= 1e-4):.1%} "
                  f"| {excess.max():.1e} | {filled} | {len(fresh)} | {missing / len(fresh):.0%} |", flush=True)


if __name__ == "__main__":
    main()
