"""Where a solve starts: the planner's start-point policy (:class:`StartPolicy`), one strategy per kind of body.

A warm solve starts from the plan or torques it is given, and for a plan to another goal from the best of it
and it moved onto the new goal: by the optimum's first-order sensitivity to the goal when the plan carries one
(:class:`~comanip.planning.goal_sensitivity.GoalSensitivity`), otherwise by joint-space minimum-jerk corrections;
from an arm reach library's ready pose its nearest plans compete. A cold solve starts from minimum-jerk reaches,
ranked by their objective, and from the solved reaches of a point mass's :class:`ReachLibrary` (turned and scaled
to the goal) or an arm's :class:`ArmReachLibrary` (moved onto the goal), as ``SolverOptions.cold_search`` says.

What a point mass and an arm do differently (their reach libraries, how a plan's goal move becomes a joint move,
which minimum-jerk guesses a cold search runs) lives in the two strategies,
:class:`~comanip.planning.starts.point_mass_starts.PointMassStarts` and
:class:`~comanip.planning.starts.arm_starts.ArmStarts`; the planner's body kind
(:mod:`comanip.planning.body_kind`) builds the one its body needs.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from comanip.arguments import as_matrix
from comanip.caching.buffered_function import BufferedFunction
from comanip.model import ReachingModel
from comanip.planning.plan import Plan
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.solver_options import SolverOptions
from comanip.planning.starts.initial_guess import LinearDynamics, guess_durations, minimum_jerk_torques, retargeted_torques


class StartPolicy(ABC):
    """The starts of a planner's solves (module docstring); a kind of body's strategy, built with the planner.

    Args:
        model: the model planned for.
        options: the planner's ``SolverOptions`` (``cold_search``, ``n_starts``, ``narrow_ratio``,
            ``far_warm_start``, ``arm_library``).
        problem: the reach problem.
        solver: the planner's solver strategy: it ranks the starts (their objectives and joint limits), and a point
            mass's reach library solves its entries with it.
    """

    linear_dynamics: LinearDynamics | None = None
    """A linear body's constant M and G (its guesses' inverse dynamics in one step); None for other bodies."""

    def __init__(self, model: ReachingModel, options: SolverOptions, problem: ReachProblem, solver: ReachSolver):
        self.model, self.options, self.problem, self.solver = model, options, problem, solver
        self.curvature = solver.curvature
        """The Newton method's terms (None for IPOPT): warm starts are predicted and moved with them."""
        body, H = model.body, model.H
        self.torque_box = (np.tile(-body.tau_max, (H, 1)), np.tile(body.tau_max, (H, 1)))
        self.unbounded = not np.isfinite(body.tau_max).any()
        self.kinematics = BufferedFunction(body.kinematics_function)

    def from_arm_library(self, start) -> bool:
        """Whether a cold solve from ``start`` (nx,) starts from an arm reach library (its ready pose)."""
        return False

    @abstractmethod
    def cold_starts(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The guesses (H, n) a cold solve runs (``SolverOptions.cold_search``); ``goal_q`` (n,): the goal's inverse
        kinematics, if known."""

    def fill_library(self, params: ReachParameters) -> None:
        """Solve the reach-library entries a cold solve of ``params`` would start from and its library lacks, before
        the solve asks for its starts (a library the solves only read; none here)."""

    @abstractmethod
    def searched_guesses(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The minimum-jerk guesses (H, n) a cold solve without a reach library runs."""

    @abstractmethod
    def joint_shift(self, mean: np.ndarray | None, goal_move: np.ndarray) -> np.ndarray:
        """The joint move (n,) that moves the end of a plan's mean path (H+1, nx) by ``goal_move`` (d,), m."""

    def mean_path(self, torque: np.ndarray, params: ReachParameters) -> np.ndarray | None:
        """The mean path (H+1, nx) of torques (H, n) for the reach ``params``, where this kind's moves of a plan need
        it (a linear body's do not: None)."""
        return None

    def moved_onto_goal(self, torque: np.ndarray, planned: ReachParameters, params: ReachParameters,
                        goal_q: np.ndarray | None = None) -> np.ndarray:
        """Torques (H, n) of a plan for the reach ``planned``, the same moved onto the goal of ``params`` by
        :meth:`retargeted`, or a fresh minimum-jerk reach from the start to it (:meth:`cold_guesses`, to ``goal_q``
        (n,) if given: a goal moved far lies where the plan's reward does not reach), whichever starts ``params``'
        solve lowest (:meth:`lowest_objective`)."""
        moved = self.retargeted(torque, self.mean_path(torque, planned), planned.goal, params.goal)
        return self.lowest_objective(moved + self.cold_guesses(params, self.options.n_starts, goal_q), params)

    def warm_candidates(self, params: ReachParameters) -> list[np.ndarray]:
        """Starts (H, n) that compete with a warm start to another goal besides its own moves (none here)."""
        return []

    def guesses(self, params: ReachParameters, warm_start, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The starts (H, n) of a solve; ``goal_q`` (n,): the goal's inverse kinematics from the start, if known."""
        model, goal, width = self.model, params.goal, params.width
        if warm_start is None:
            return self.cold_starts(params, goal_q)
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
        candidates += self.warm_candidates(params)
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
        model = self.model
        return [torque] + retargeted_torques(model.body, model.h, model.H, torque, self.joint_shift(mean, goal - planned_goal),
                                             guess_durations(model.duration, 4), mean, self.linear_dynamics)

    def lowest_objective(self, candidates: list[np.ndarray], params: ReachParameters) -> np.ndarray:
        """The candidate torques (H, n), clipped to the torque bounds, of lowest objective among those whose mean
        path keeps the joint limits (all candidates if none does)."""
        low, high = self.torque_box
        if self.unbounded:  # no torque bound (the point masses): clipping would only copy
            return min(candidates, key=lambda c: self.solver.start_rank(c, params))
        return min((np.clip(c, low, high) for c in candidates), key=lambda c: self.solver.start_rank(c, params))

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

