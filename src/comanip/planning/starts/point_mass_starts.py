"""The start policy of a point mass (:class:`PointMassStarts`): its cold starts from the solved reaches of its
:class:`~comanip.planning.starts.reach_library.ReachLibrary` (turned and scaled to the goal; from a moving start
superposed on a stop of its motion), or from every minimum-jerk guess where local optima compete.
"""

from __future__ import annotations

import numpy as np

from comanip.model import ReachingModel
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.solver_options import SolverOptions
from comanip.planning.starts.initial_guess import LinearDynamics, guess_durations, linear_dynamics_of, minimum_jerk_torques
from comanip.planning.starts.reach_library import ReachLibrary, is_symmetric
from comanip.planning.starts.start_policy import StartPolicy


class PointMassStarts(StartPolicy):
    """Where a point mass's solves start (:class:`~comanip.planning.starts.start_policy.StartPolicy`, whose arguments
    it takes)."""

    def __init__(self, model: ReachingModel, options: SolverOptions, problem: ReachProblem, solver: ReachSolver):
        super().__init__(model, options, problem, solver)
        body = model.body
        self.linear_dynamics = linear_dynamics_of(body)
        self.damped_drift = _damped_drift(body, self.linear_dynamics)
        """D⁻¹ M (n, n): how far (m) its damping alone carries it per m/s of start velocity; None when undamped."""
        # the joint move (n,) per task-space move (d,): the pseudo-inverse of its constant Jacobian
        self.task_to_joint_shift = np.linalg.pinv(np.asarray(body.kinematics_function(np.zeros(body.n))[1]))
        self.library = self._reach_library()

    def _reach_library(self) -> ReachLibrary | None:
        """Solved reaches to start 'ranked' cold solves from (:mod:`comanip.planning.starts.reach_library`), for a
        point mass whose objective is unchanged by turning and shifting the problem; None otherwise."""
        model = self.model
        if self.options.cold_search != "ranked" or model.d != model.n or model.state_size % model.n:
            return None
        if not is_symmetric(self.problem):
            return None
        return ReachLibrary(self.solver, self.searched_guesses, model.n, model.state_size, model.width)

    def joint_shift(self, mean: np.ndarray | None, goal_move: np.ndarray) -> np.ndarray:
        """x_ee linear in q: the goal's move (d,) times the constant pseudo-inverse of the Jacobian (the mean path is
        not needed)."""
        return self.task_to_joint_shift @ goal_move

    def cold_starts(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The guesses a cold solve runs (``SolverOptions.cold_search``).

'all', or a point mass without a reach library (not symmetric): :meth:`searched_guesses`. 'ranked', for a
        symmetric point mass: the
        candidate of lowest objective (evaluating one costs about a hundredth of solving from it) among the
        minimum-jerk guesses and the nearest solved reach of the :class:`ReachLibrary` (from a moving start:
        :meth:`stopped_reaches`). Where
        several local optima compete (a goal farther than ``narrow_ratio`` widths from the start or from where a stop
        of its motion ends) a minimum-jerk guess of lowest objective can end on a worse one: the candidates are then
        the library's plans near each local optimum (:meth:`ReachLibrary.local_optima`, superposed on a stop from a
        moving start that its damping stops in place), which lie close to their optima, so that their objectives
        rank them as their solves would end; from a start whose motion carries the hand on, every minimum-jerk
        guess. The full search stays ``cold_search="all"``;
        benchmarks/cold_quality.py checks the ranked starts against it under the cold-search rule (within 1e-4 of
        its objective in at least 98 % of random problems, never 1e-3 worse, as many successes).
        The library's entries are those solved before (:meth:`fill_library`); without them a narrow goal runs every
        minimum-jerk guess.
        """
        if self.library is None:
            return self.searched_guesses(params, goal_q)
        motion = _motion(params.start, self.model.n)
        moving = bool(np.any(motion))
        narrow = self.narrow_after_stops(params, motion)
        if self._carries_on(motion, narrow):
            # its local optima are not the library's (ranked starts built from them ended above the full search on
            # planar goals, and so did every subset of the guesses tried: benchmarks/drifting_starts.py; a library of
            # solved moving-start reaches meets the cold-search rule only on a grid where nearly every problem needs
            # a new entry: studies/does_a_library_of_moving_start_reaches_pay_off/)
            return self.cold_guesses(params, self.options.n_starts)
        if moving:
            candidates = self.stopped_reaches(params, motion, every_optimum=narrow)
        elif narrow:
            candidates = self.library.local_optima(params)
        else:
            turned = self.library.guess(params)
            candidates = [] if turned is None else [turned]
        if narrow:
            return [self.lowest_objective(candidates, params)] if candidates else self.cold_guesses(params, self.options.n_starts)
        guesses = self.cold_guesses(params, self.options.n_starts)
        objectives = [self.objective(guess, params) for guess in guesses]
        first_best = min(range(len(guesses)), key=objectives.__getitem__)
        best_guess = guesses[first_best]
        if not candidates:  # the goal at the start, or an entry not solved: as without a library
            return [best_guess]
        scored = [(self.objective(candidate, params), candidate) for candidate in candidates] + \
            [(objectives[first_best], best_guess)]  # the guess's objective as evaluated above
        return [min(scored, key=lambda pair: pair[0])[1]]

    def carried_on(self, params: ReachParameters) -> bool:
        """Whether a point mass's start moves so that a stop of its motion ends away from the start and the goal lies
        beyond ``narrow_ratio`` widths from the start or from where a stop ends: a 'ranked' cold solve then runs
        every minimum-jerk guess (:meth:`cold_starts`)."""
        motion = _motion(params.start, self.model.n)
        return self._carries_on(motion, self.narrow_after_stops(params, motion))

    def _carries_on(self, motion: np.ndarray, narrow: bool) -> bool:
        """:meth:`carried_on` for the start's ``motion`` (nx,, its position zeroed) and whether the goal is narrow
        after its stops (:meth:`narrow_after_stops`)."""
        return narrow and bool(np.any(motion)) and bool(self.stops(motion).any())

    def stopped_reaches(self, params: ReachParameters, motion: np.ndarray, every_optimum: bool = False) -> list[np.ndarray]:
        """A point mass's starts (H, n) from a moving start: for each minimum-jerk duration T, a stop from the start's
        velocity v0 superposed on the library's reach from where the stop ends to the goal (the mean is affine in the
        torques and the start, so the sum ends at the goal at rest); ``every_optimum``: on each of the library's plans
        near a local optimum (:meth:`ReachLibrary.local_optima`) instead. A lightly damped hand stops v0·T/2 on, where a
        minimum-jerk stop with a free end comes to rest (the quintic's t⁵ term vanishes); one whose damping alone
        would stop it sooner (D⁻¹ M v0 on) is braked back to its start position, the stop that serves strongly
        damped hands better (benchmarks/cold_quality.py). Stops whose reach the library does not have yet are left
        out. ``motion`` (nx,): the start with its position zeroed."""
        model = self.model
        durations = guess_durations(model.duration, self.options.n_starts)
        stops = self.stops(motion)
        brakes = minimum_jerk_torques(model.body, model.h, model.H, motion, stops[:, None, :], durations, self.linear_dynamics)
        reaches = {}  # one library reach per distinct stop (those braked back to the start share one)
        for stop, reach in zip(map(tuple, stops), self.stopped_starts(params, stops)):
            if stop not in reaches:
                found = self.library.local_optima(reach) if every_optimum else [self.library.guess(reach)]
                reaches[stop] = [torque for torque in found if torque is not None]
        return [reach + brake for stop, brake in zip(map(tuple, stops), brakes) for reach in reaches[stop]]

    def stopped_starts(self, params: ReachParameters, stops: np.ndarray) -> list[ReachParameters]:
        """The reaches from rest where each stop (k, n) of the start's motion ends, to the goal at its width."""
        n, at_rest = self.model.n, np.zeros(self.model.state_size - self.model.n)
        return [ReachParameters(np.r_[params.start[:n] + stop, at_rest], params.goal, params.width) for stop in stops]

    def fill_library(self, params: ReachParameters) -> None:
        """Solve the reach-library entries that a cold solve of ``params`` starts from and the library lacks: the
        entry nearest to the reach from rest (or, beyond ``narrow_ratio`` widths, the two around it), or to each reach
        from where a stop of a moving start ends (:meth:`stopped_reaches`); none where the starts use no library."""
        if self.library is None:
            return
        motion = _motion(params.start, self.model.n)
        narrow = self.narrow_after_stops(params, motion)
        if self._carries_on(motion, narrow):
            return
        reaches = self.stopped_starts(params, self.stops(motion)) if np.any(motion) else [params]
        for reach in reaches:
            self.library.fill(reach, bracket=narrow)

    def narrow_after_stops(self, params: ReachParameters, motion: np.ndarray) -> bool:
        """:meth:`narrow`, or the goal farther than ``narrow_ratio`` widths from where a stop of the start's motion
        ends (:meth:`stops`; ``motion`` (nx,): the start with its position zeroed). A point mass's test for
        competing local optima."""
        ends = params.start[: self.model.n] + self.stops(motion)
        return self.narrow(params) or \
            bool(np.any(np.linalg.norm(params.goal - ends, axis=1) > self.options.narrow_ratio * params.width))

    def stops(self, motion: np.ndarray) -> np.ndarray:
        """Where a point mass's stops from a moving start end (``n_starts``, n), relative to its start position (m):
        v0·T/2 on for each minimum-jerk duration T, or zero (back at the start) where its damping alone would stop
        it sooner (:meth:`stopped_reaches`). ``motion`` (nx,): the start with its position zeroed."""
        n = self.model.n
        durations = guess_durations(self.model.duration, self.options.n_starts)
        velocity = motion[n:2 * n]
        stops = 0.5 * durations[:, None] * velocity
        drift = np.inf if self.damped_drift is None else np.linalg.norm(self.damped_drift @ velocity)
        stops[np.linalg.norm(stops, axis=1) > drift] = 0.0
        return stops

    def searched_guesses(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The minimum-jerk guesses a cold solve without a reach library runs: all for 'all' and for a goal beyond
        ``narrow_ratio`` widths, otherwise the one of lowest objective."""
        guesses = self.cold_guesses(params, self.options.n_starts, goal_q)
        if self.options.cold_search == "all" or len(guesses) == 1 or self.narrow(params):
            return guesses
        return [min(guesses, key=lambda guess: self.objective(guess, params))]


def _motion(start: np.ndarray, n: int) -> np.ndarray:
    """The start state (nx,) with its position (the first n entries) zeroed: its motion alone."""
    motion = start.copy()
    motion[:n] = 0.0
    return motion


def _damped_drift(body, linear_dynamics: LinearDynamics | None) -> np.ndarray | None:
    """D⁻¹ M (n, n) of a linear body with mass matrix M and damping D (M v' = -D v carries it D⁻¹ M v0 from a start
    velocity v0); None without linear dynamics or when D is singular (the damping alone does not stop it)."""
    if linear_dynamics is None:
        return None
    mass, damping = linear_dynamics.mass, np.asarray(body.damping, dtype=float)
    if np.linalg.matrix_rank(damping) < len(damping):
        return None
    return np.linalg.solve(damping, mass)
