"""Where a solve starts: the planner's start-point policy (:class:`StartPolicy`).

A warm solve starts from the plan or torques it is given, and for a plan to another goal from the best of it
and it moved onto the new goal: by the optimum's first-order sensitivity to the goal when the plan carries one
(:class:`~comanip.planning.goal_sensitivity.GoalSensitivity`), otherwise by joint-space minimum-jerk corrections;
from an arm reach library's ready pose its nearest plans compete. A cold solve starts from minimum-jerk reaches,
ranked by their objective, and from the solved reaches of a point mass's :class:`ReachLibrary` (turned and scaled
to the goal) or an arm's :class:`ArmReachLibrary` (moved onto the goal), as ``SolverOptions.cold_search`` says.
"""

from __future__ import annotations

import numpy as np

from comanip.arguments import as_matrix
from comanip.caching.buffered_function import BufferedFunction
from comanip.model import ReachingModel
from comanip.planning.plan import Plan
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.starts.arm_reach_library import CANDIDATE_ENTRIES, WARM_CANDIDATE_ENTRIES, ArmReachLibrary, bundled_library
from comanip.planning.starts.initial_guess import (LinearDynamics, brake_durations, braked_torques, guess_durations,
                                                   linear_dynamics_of, minimum_jerk_torques, retargeted_torques)
from comanip.planning.starts.reach_library import ReachLibrary, is_symmetric


class StartPolicy:
    """The starts of a planner's solves (module docstring); built by the :class:`~comanip.planning.planner.Planner`.

    Args:
        model: the model planned for.
        options: the planner's ``SolverOptions`` (``cold_search``, ``n_starts``, ``narrow_ratio``,
            ``far_warm_start``, ``arm_library``).
        problem: the reach problem.
        solver: the planner's solver strategy: it ranks the starts (their objectives and joint limits), and a point
            mass's reach library solves its entries with it from :meth:`searched_guesses`.
    """

    def __init__(self, model: ReachingModel, options, problem: ReachProblem, solver: ReachSolver):
        self.model, self.options, self.problem, self.solver = model, options, problem, solver
        self.curvature = solver.curvature
        """The Newton method's terms (None for IPOPT): warm starts are predicted and moved with them."""
        body, H = model.body, model.H
        self.torque_box = (np.tile(-body.tau_max, (H, 1)), np.tile(body.tau_max, (H, 1)))
        self.unbounded = not np.isfinite(body.tau_max).any()
        self.linear_dynamics = linear_dynamics_of(body) if body.is_linear else None
        self.damped_drift = _damped_drift(body, self.linear_dynamics)
        """D⁻¹ M (n, n) of a linear body: how far (m) its damping alone carries it per m/s of start velocity; None for
        other bodies and undamped ones."""
        # a linear body's joint move (n,) per task-space move (d,): the pseudo-inverse of its constant Jacobian
        self.task_to_joint_shift = np.linalg.pinv(np.asarray(body.kinematics_function(np.zeros(body.n))[1])) \
            if body.is_linear else None
        self.kinematics = BufferedFunction(body.kinematics_function)
        self.library = self._reach_library()
        ranked_arm = options.cold_search == "ranked" and not body.is_linear
        self.arm_library = self._arm_reach_library() if ranked_arm else None

    def _arm_reach_library(self) -> ArmReachLibrary | None:
        """The arm's reach library: ``options.arm_library`` (it must be this model's) or the shipped one."""
        if self.options.arm_library is None:
            return bundled_library(self.model)
        library = ArmReachLibrary.load(self.options.arm_library)
        if not library.is_for(self.model):
            raise ValueError(f"arm_library {self.options.arm_library!r} was solved for another model; a library applies "
                             f"to the model it was made for (comanip library --preset <this model's YAML>)")
        return library

    def _reach_library(self) -> ReachLibrary | None:
        """Solved reaches to start 'ranked' cold solves from (:mod:`comanip.planning.starts.reach_library`), for a
        point mass whose objective is unchanged by turning and shifting the problem; None otherwise."""
        model = self.model
        if self.options.cold_search != "ranked" or not model.body.is_linear or model.d != model.n or model.state_size % model.n:
            return None
        if not is_symmetric(self.problem):
            return None
        return ReachLibrary(self.solver, self.searched_guesses, model.n, model.state_size, model.width)

    def from_arm_library(self, start) -> bool:
        """Whether a cold solve from ``start`` (nx,) starts from the arm reach library (its ready pose)."""
        return self.arm_library is not None and self.arm_library.serves(start)

    def guesses(self, params: ReachParameters, warm_start, budgeted: bool = False,
                goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The starts (H, n) of a solve; ``goal_q`` (n,): the goal's inverse kinematics from the start, if known."""
        model, start, goal, width = self.model, params.start, params.goal, params.width
        if warm_start is None:
            return self.cold_starts(params, budgeted, goal_q)
        torque = warm_start.torque if isinstance(warm_start, Plan) else warm_start
        torque = as_matrix("warm_start", torque, (model.H, model.n), "torques, N·m or N")
        if not (isinstance(warm_start, Plan) and warm_start.goal.shape == goal.shape
                and warm_start.mean.shape[0] == model.H + 1 and not np.array_equal(warm_start.goal, goal)):
            return [torque]
        # a plan for another goal: also try it moved onto the new goal (by the tangential predictor if the plan
        # carries its sensitivity: it gave the best start in 398 of 400 warm point-mass solves, against the
        # minimum-jerk retargeting's 1), and start from the best
        predicted = self.predicted(warm_start, params)
        candidates = [torque, predicted] if predicted is not None else \
            self.retargeted(torque, warm_start.mean, warm_start.goal, goal)
        if self.from_arm_library(start):
            # the solved reach nearest to the goal competes too: on 50 chained warm franka_rest solves to goals
            # moved by up to 5 cm per axis it was the best start 48 times (15 → 10 Newton iterations, J within 3e-9)
            candidates += self.library_candidates(params, WARM_CANDIDATE_ENTRIES)
        end = warm_start.ee_mean[-1]
        if predicted is not None:  # where the predicted start ends (the mean is affine in the torques)
            end = end + self.curvature.final_position_change(predicted - torque)
        if np.linalg.norm(end - goal) > self.options.far_warm_start * width:
            # far beyond the goal's reward (it underflows there): fresh reaches compete too
            candidates += self.cold_guesses(params, self.options.n_starts)
        return [self.lowest_objective(candidates, params)]

    def predicted(self, warm_start: Plan, params: ReachParameters) -> np.ndarray | None:
        """The first-order prediction of the optimal torques (H, n) for ``goal`` from a plan that carries its
        goal sensitivity for this planner's problem (same start and width, another goal): tau* + (d tau*/d goal)
        (goal - its goal), the tangential predictor of parametric optimisation; None for any other warm start.
        For goals moved by a few cm it starts closer to the optimum than the retargeted plan."""
        sensitivity = warm_start.goal_sensitivity
        if sensitivity is None or not sensitivity.is_for(self.curvature) or warm_start.width != params.width \
                or not np.array_equal(warm_start.start, params.start):
            return None
        model = self.model
        return warm_start.torque + (sensitivity.matrix() @ (params.goal - warm_start.goal)).reshape(model.H, model.n)

    def retargeted(self, torque: np.ndarray, mean: np.ndarray, planned_goal: np.ndarray, goal: np.ndarray) -> list[np.ndarray]:
        """A plan's torques (H, n) for ``planned_goal`` (d,) and the same moved onto ``goal`` (d,) by joint-space
        minimum-jerk corrections of four durations (:func:`retargeted_torques`, along its mean (H+1, nx))."""
        model, body = self.model, self.model.body
        if self.linear_dynamics is not None:  # x_ee linear in q: one constant pseudo-inverse
            shift_q = self.task_to_joint_shift @ (goal - planned_goal)
        else:
            J = np.asarray(body.kinematics_function(mean[-1, : model.n])[1])
            shift_q = np.linalg.lstsq(J, goal - planned_goal, rcond=None)[0]
        return [torque] + retargeted_torques(body, model.h, model.H, torque, shift_q, guess_durations(model.duration, 4),
                                             mean, self.linear_dynamics)

    def lowest_objective(self, candidates: list[np.ndarray], params: ReachParameters) -> np.ndarray:
        """The candidate torques (H, n), clipped to the torque bounds, of lowest objective among those whose mean
        path keeps the joint limits (all candidates if none does)."""
        low, high = self.torque_box
        if self.unbounded:  # no torque bound (the point masses): clipping would only copy
            return min(candidates, key=lambda c: self.solver.start_rank(c, params))
        return min((np.clip(c, low, high) for c in candidates), key=lambda c: self.solver.start_rank(c, params))

    def cold_starts(self, params: ReachParameters, budgeted: bool = False, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The guesses a cold solve runs (``SolverOptions.cold_search``).

        An arm at the ready pose of its reach library: :meth:`arm_library_starts`. 'all': every minimum-jerk
        guess; another nonlinear body or start: :meth:`searched_guesses`. 'ranked', for a symmetric point mass: the
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
        A ``budgeted`` solve (max_wall_time given) uses only library reaches solved before: solving a new one is a
        whole cold search outside the budget; without them a narrow goal
        runs every minimum-jerk guess.
        """
        start, goal, width = params.start, params.goal, params.width
        if self.from_arm_library(start):
            return self.arm_library_starts(params, goal_q)
        if self.library is None:
            return self.searched_guesses(params, goal_q)
        motion = _motion(start, self.model.n)
        moving = bool(np.any(motion))
        narrow = self.narrow_after_stops(params, motion)
        if self._carries_on(motion, narrow):
            # its local optima are not the library's (ranked starts built from them ended above the full search on
            # planar goals, and so did every subset of the guesses tried: benchmarks/drifting_starts.py; a library of
            # solved moving-start reaches meets the cold-search rule only on a grid where nearly every problem needs
            # a new entry: studies/does_a_library_of_moving_start_reaches_pay_off/)
            return self.cold_guesses(params, self.options.n_starts)
        if moving:
            candidates = self.stopped_reaches(params, motion, budgeted, every_optimum=narrow)
        elif narrow:
            candidates = self.library.local_optima(start, goal, width, solve_missing=not budgeted)
        else:
            turned = self.library.guess(start, goal, width, solve_missing=not budgeted)
            candidates = [] if turned is None else [turned]
        if narrow:
            return [self.lowest_objective(candidates, params)] if candidates else self.cold_guesses(params, self.options.n_starts)
        guesses = self.cold_guesses(params, self.options.n_starts)
        objectives = [self.objective(guess, params) for guess in guesses]
        first_best = min(range(len(guesses)), key=objectives.__getitem__)
        best_guess = guesses[first_best]
        if not candidates:  # the goal at the start, or a budgeted solve without the entry: as without a library
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

    def stopped_reaches(self, params: ReachParameters, motion: np.ndarray, budgeted: bool = False,
                        every_optimum: bool = False) -> list[np.ndarray]:
        """A point mass's starts (H, n) from a moving start: for each minimum-jerk duration T, a stop from the start's
        velocity v0 superposed on the library's reach from where the stop ends to the goal (the mean is affine in the
        torques and the start, so the sum ends at the goal at rest); ``every_optimum``: on each of the library's plans
        near a local optimum (:meth:`ReachLibrary.local_optima`) instead. A lightly damped hand stops v0·T/2 on, where a
        minimum-jerk stop with a free end comes to rest (the quintic's t⁵ term vanishes); one whose damping alone
        would stop it sooner (D⁻¹ M v0 on) is braked back to its start position, the stop that serves strongly
        damped hands better (benchmarks/cold_quality.py). Stops whose reach the library does not have for a
        budgeted solve are left out. ``motion`` (nx,): the start with its position zeroed."""
        model, start = self.model, params.start
        n = model.n
        durations = guess_durations(model.duration, self.options.n_starts)
        stops = self.stops(motion)
        brakes = minimum_jerk_torques(model.body, model.h, model.H, motion, stops[:, None, :], durations, self.linear_dynamics)
        at_rest = np.zeros(model.state_size - n)

        def reaches_from(stop) -> list[np.ndarray]:
            stopped = np.r_[start[:n] + stop, at_rest]
            if every_optimum:
                return self.library.local_optima(stopped, params.goal, params.width, solve_missing=not budgeted)
            reach = self.library.guess(stopped, params.goal, params.width, solve_missing=not budgeted)
            return [] if reach is None else [reach]

        back_at_start = reaches_from(np.zeros(n)) if not stops.any(axis=1).all() else None  # one reach for every such stop
        reaches = [reaches_from(stop) if stop.any() else back_at_start for stop in stops]
        return [reach + brake for found, brake in zip(reaches, brakes) for reach in found]

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

    def arm_library_starts(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """An arm's cold starts from its ready pose (:mod:`comanip.planning.starts.arm_reach_library`): first the
        lowest-objective torques (H, n) among the minimum-jerk guesses and the plans of the nearest library
        entries, each as solved and moved onto the goal; then the minimum-jerk guesses, which the planner runs
        only if no start before them converged."""
        guesses = self.cold_guesses(params, self.options.n_starts, goal_q)
        candidates = guesses + self.library_candidates(params, CANDIDATE_ENTRIES)
        return [self.lowest_objective(candidates, params)] + guesses

    def library_candidates(self, params: ReachParameters, entries: int) -> list[np.ndarray]:
        """The plans (H, n) of the arm reach library's ``entries`` entries nearest to ``goal`` (d,), each as solved
        and moved onto the goal (:meth:`retargeted`); the start has the library's joint positions, and if it
        moves, each candidate gets the braking moves of :func:`braked_torques` instead."""
        library, model, candidates, goal = self.arm_library, self.model, [], params.goal
        velocity = params.start[model.n:2 * model.n]
        for entry_goal, torque in library.nearest(goal, entries):
            entry_params = ReachParameters(library.start, entry_goal, library.width)
            mean = self.curvature.mean_path(self.curvature.value_and_data(np.ravel(torque), entry_params).data)
            moved = self.retargeted(torque, mean, entry_goal, goal)
            if np.any(velocity):
                moved = [braked for candidate in moved for braked in
                         braked_torques(model.body, model.h, model.H, candidate, velocity, brake_durations(model.duration), mean)]
            candidates += moved
        return candidates

    def searched_guesses(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The minimum-jerk guesses a cold solve without a reach library runs: all for 'all' and for a point mass's
        goal beyond ``narrow_ratio`` widths, otherwise the point mass's one of lowest objective; for a nonlinear body
        at rest all but the one of highest objective beyond ``arm_narrow_ratio`` widths, else all."""
        guesses = self.cold_guesses(params, self.options.n_starts, goal_q)
        if self.options.cold_search == "all" or len(guesses) == 1:
            return guesses
        if not self.model.body.is_linear:
            if np.any(_motion(params.start, self.model.n)) or not self.narrow(params, self.options.arm_narrow_ratio):
                return guesses
            return sorted(guesses, key=lambda guess: self.objective(guess, params))[:-1]
        if self.narrow(params):
            return guesses
        return [min(guesses, key=lambda guess: self.objective(guess, params))]

    def narrow(self, params: ReachParameters, ratio: float | None = None) -> bool:
        """True when the goal is farther than ``ratio`` (default ``narrow_ratio``) widths from the start's
        end-effector position."""
        ratio = self.options.narrow_ratio if ratio is None else ratio
        position = self.kinematics(params.start[: self.model.n])[0].ravel()
        return bool(np.linalg.norm(params.goal - position) > ratio * params.width)

    def cold_guesses(self, params: ReachParameters, count: int, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """Minimum-jerk reaches to ``goal_q`` (n,), the inverse-kinematics solution from the start (computed
        when None), ``count`` durations."""
        model, start = self.model, params.start
        goal_q = model.body.inverse_kinematics(params.goal, start[: model.n]) if goal_q is None else goal_q
        return list(minimum_jerk_torques(model.body, model.h, model.H, start, goal_q, guess_durations(model.duration, count),
                                         self.linear_dynamics))

    def objective(self, torque: np.ndarray, params: ReachParameters) -> float:
        """J (or J normalised, for comparisons at fixed parameters) of torques (H, n)."""
        return self.solver.objective(torque, params)


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
