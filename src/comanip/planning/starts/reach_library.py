"""Solved reaches of a symmetric point mass, turned and scaled into initial guesses for cold solves.

A point mass whose end effector is its position, with isotropic inertia, damping, motor noise and goal
covariance (the point-mass presets), plans the same reach in every direction and from every position: the
optimal torques for a goal at offset D·u from a start at rest are those for D·e_1 with every torque vector
turned by an orthogonal map that takes e_1 to u. And the problem is nearly invariant under scaling lengths
and widths together, so one solved reach per reach distance over goal width D/w serves every (D, w) with
about that ratio, its torques scaled by the distance.

:class:`ReachLibrary` keeps such reaches (start at rest at the origin, goal D_k·e_1 at the model's width w_0,
D_k/w_0 on a geometric grid), each solved on first use and kept for the planner's lifetime. A cold solve
from the nearest one needs three to four Newton iterations instead of the seven of the best minimum-jerk
guess (benchmarks/README.md). Deterministic: an entry depends on its grid point only, not on the order of
the solves that asked for it.

Far, narrow reaches (beyond the planner's ``narrow_ratio`` widths) have several local optima, which differ in the
step where the hand brakes; which one is lowest changes between grid points. An entry therefore keeps every
distinct plan its full search converged to, and :meth:`ReachLibrary.local_optima` offers all those of the two
entries around a goal, each also run a little faster and slower (:func:`at_pace`): near-converged starts whose
objectives rank them as their solves end.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from comanip.optim import CONVERGED
from comanip.planning.path_limits import LIMIT_TOLERANCE
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reflection import reflection_onto
from comanip.planning.reach_solver import ReachSolver, rank

GRID_RATIO = 1.4
"""Ratio of successive entries' D/w: a query's is at most √1.4 ≈ 1.18 times off its entry's."""
WIDTH_RATIO = 2.0
"""Ratio of successive entries' widths: the scaling is only nearly exact (the effort does not scale), and a
query's width is at most √2 times off its entry's (with one width for all, a 5 mm query from a 50 mm entry
took three times the iterations)."""
PACES = (0.9, 0.95, 1.0, 1.05, 1.1)
"""Paces at which :meth:`ReachLibrary.local_optima` also runs each entry's plans: the local optima of a far, narrow
reach differ in the step at which the hand brakes, and the best one's step moves between grid points (with the
entries' plans at their own pace only, the ranked start missed the full search's optimum on some planar goals;
benchmarks/cold_quality.py --workspace checks these paces)."""
LOCAL_OPTIMUM_TOLERANCE = 1e-6
"""Relative objective difference below which two converged plans of one cold search count as the same local
optimum (an entry keeps one plan per local optimum)."""
SYMMETRY_TOLERANCE = 1e-9
"""Relative objective difference under a random turn and shift below which a model counts as symmetric."""


def at_pace(torque: np.ndarray, pace: float) -> np.ndarray:
    """Torques (H, n) of the same reach run ``pace`` times as fast: tau'(t) = pace² tau(pace t), which moves an
    undamped mass along the same path in 1/pace of the time; interpolated between steps, zero past the horizon."""
    steps = np.arange(torque.shape[0]) + 0.5
    return pace**2 * np.stack([np.interp(pace * steps, steps, column, right=0.0) for column in torque.T], axis=1)


def is_symmetric(problem: ReachProblem, seed: int = 0) -> bool:
    """True when the problem's J(tau, s0, g, w) (a body with end effector = position, d = n) is unchanged, to
    SYMMETRY_TOLERANCE, by turning every vector (torques (H, n), start positions, velocities and activation
    states, goal) with a random orthogonal map and shifting positions and goal by a random offset.

    Checked at random torques with the goal where their mean path passes mid-horizon, so that the expected
    reward (and with it the shape of the covariance) weighs in J.
    """
    model = problem.model
    n, width = model.n, model.width
    rng = np.random.default_rng(seed)
    turn = np.linalg.qr(rng.normal(size=(n, n)))[0]
    shift = rng.normal(scale=0.1, size=n)
    torque = rng.normal(scale=2.0, size=(model.H, n))
    start = rng.normal(scale=0.05, size=model.state_size)
    rollout = problem.trajectory(tau=np.ravel(torque), s0=start, goal=np.zeros(n), width=width)
    goal = np.asarray(rollout["ee_mean"])[:, model.H // 2] + 0.5 * width * rng.normal(size=n)
    moved = (start.reshape(-1, n) @ turn.T).ravel()
    moved[:n] += shift
    reference = problem.objective_value(torque, start, goal, width)
    turned = problem.objective_value(torque @ turn.T, moved, turn @ goal + shift, width)
    return bool(np.isfinite(reference) and abs(turned - reference) <= SYMMETRY_TOLERANCE * abs(reference))


class ReachLibrary:
    """Rest-to-goal reaches of one symmetric point-mass model, solved when asked to (:meth:`fill`; module docstring).

    An entry keeps every distinct plan its cold search converged to, lowest objective first: past
    ``narrow_ratio`` widths several local optima compete, and which is lowest changes between grid points.

    Args:
        solver: the planner's solver strategy, which solves an entry from ``starts``.
        starts: the starts (each torques (H, n)) of the planner's cold search for a reach's parameters (the start
            policy's minimum-jerk guesses).
        n: dimension of the point mass (= d).
        state_size: length of the model's state (2n plus any activation states).
        width: w_0 (m), the width grid's anchor (the model's default).
    """

    def __init__(self, solver: ReachSolver, starts: Callable[[ReachParameters], list[np.ndarray]], n: int,
                 state_size: int, width: float):
        self.solver, self.starts, self.n, self.state_size, self.width = solver, starts, n, state_size, float(width)
        self._entries: dict[tuple[int, int], list[list[np.ndarray]]] = {}
        """Per grid point, its plans (lowest objective first), each at every pace of :data:`PACES`."""

    def guess(self, params: ReachParameters) -> np.ndarray | None:
        """Torques (H, n) of the nearest entry's best plan turned towards the goal (n,) and scaled to its distance from
        the start's position, for the start at rest there (a moving start adds its own correction); None when the
        goal is at the start (or its distance overflows), or when the entry is not solved yet (:meth:`fill`)."""
        found = self._near_entries(params, bracket=False)
        return found[0] if found else None

    def local_optima(self, params: ReachParameters) -> list[np.ndarray]:
        """Every plan of the two entries whose D/w bracket the goal's (at the nearest width), turned and scaled as
        :meth:`guess` does, each also run at the other :data:`PACES`: torques (H, n) near each local optimum the
        goal's problem has where several compete. Empty when the goal is at the start, or an entry is not solved
        yet (:meth:`fill`)."""
        return self._near_entries(params, bracket=True)

    def fill(self, params: ReachParameters, bracket: bool) -> None:
        """Solve the entries that :meth:`local_optima` (``bracket``) or :meth:`guess` needs for the reach ``params``
        and does not have yet, each by the planner's cold search (:func:`distinct_optima`); the lookups never solve."""
        for key, _ in self._entry_keys(params, bracket):
            if key not in self._entries:
                entry_width = WIDTH_RATIO**key[1] * self.width
                entry = ReachParameters(np.zeros(self.state_size), GRID_RATIO**key[0] * entry_width * np.eye(self.n)[0],
                                        entry_width)
                optima = distinct_optima(self.solver, self.starts, entry)
                # each plan at every pace, computed once: turning and scaling commute with the change of pace
                self._entries[key] = [[plan if pace == 1.0 else at_pace(plan, pace) for pace in PACES] for plan in optima]

    def _entry_keys(self, params: ReachParameters, bracket: bool) -> list[tuple[tuple[int, int], float]]:
        """The grid points (D/w index, width index) of the nearest entry, or of both bracketing entries, for the reach
        ``params``, each with the goal's distance over the entry's (the plans' scale); empty when the goal is at the
        start or so far that its distance overflows."""
        offset = params.goal - params.start[: self.n]
        with np.errstate(over="ignore"):
            distance = float(np.linalg.norm(offset))
        if not 0.0 < distance < np.inf:
            return []
        ratio_index = np.log(distance / params.width) / np.log(GRID_RATIO)
        width_index = int(np.round(np.log(params.width / self.width) / np.log(WIDTH_RATIO)))
        ratio_indices = sorted({int(np.floor(ratio_index)), int(np.ceil(ratio_index))}) if bracket \
            else [int(np.round(ratio_index))]
        return [((index, width_index), distance / (GRID_RATIO**index * WIDTH_RATIO**width_index * self.width))
                for index in ratio_indices]

    def _near_entries(self, params: ReachParameters, bracket: bool) -> list[np.ndarray]:
        """The plans (H, n) of the nearest entry (its best only), or of both bracketing entries (all of them, each at
        every pace of :data:`PACES`), turned and scaled onto the goal; empty as :meth:`local_optima` says."""
        keys = self._entry_keys(params, bracket)
        if not keys or any(key not in self._entries for key, _ in keys):
            return []
        offset = params.goal - params.start[: self.n]
        turn = reflection_onto(offset / np.linalg.norm(offset)).T
        plans = []
        for key, scale in keys:
            kept = [paced for plan in self._entries[key] for paced in plan] if bracket \
                else [self._entries[key][0][PACES.index(1.0)]]
            plans += [scale * torque @ turn for torque in kept]
        return plans


def distinct_optima(solver: ReachSolver, starts: Callable[[ReachParameters], list[np.ndarray]],
                    params: ReachParameters) -> list[np.ndarray]:
    """A library entry: the distinct converged plans (torques (H, n), lowest objective first) of the cold search
    from ``starts(params)`` within the limits, plans whose objectives agree to ``LOCAL_OPTIMUM_TOLERANCE`` (relative)
    counting as one; the best plan when none converged."""
    results = sorted(solver.results(starts(params), params), key=rank)
    kept = []
    for result in results:
        within_limits = not result.violation > LIMIT_TOLERANCE  # IPOPT reports no violation (NaN)
        if result.status in CONVERGED and within_limits and \
                all(abs(result.fun - other.fun) > LOCAL_OPTIMUM_TOLERANCE * abs(other.fun) for other in kept):
            kept.append(result)
    return [result.x for result in kept] or [results[0].x]
