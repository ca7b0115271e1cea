"""What planning does differently for a point mass and for an arm, decided once when a planner is built
(:func:`body_kind`) and handed to the pieces that differ.

- **Point mass** (:class:`PointMass`, a linear body: constant M, G and Jacobian): the exact Hessian
  (:class:`~comanip.planning.curvature.ReachCurvature`), compiled in the background once the planner has solved a
  while; the point-mass start policy with its reach library; every goal reachable; activation stages and IPOPT
  allowed.
- **Arm** (:class:`Arm`, a nonlinear body): the approximate Hessian with secant corrections
  (:class:`~comanip.planning.linearised_curvature.LinearisedCurvature`), compiled when built; its own iteration limit
  and tolerance; the arm start policy with its reach library from the ready pose; the reachability witness before a
  solve.

This module is the only one of :mod:`comanip.planning` that asks which kind a body is.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from comanip.model import ReachingModel
from comanip.planning.curvature import ReachCurvature
from comanip.planning.linearised_curvature import LinearisedCurvature
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.solver_options import SolverOptions
from comanip.planning.starts.arm_starts import ArmStarts
from comanip.planning.starts.point_mass_starts import PointMassStarts
from comanip.planning.starts.start_policy import StartPolicy
from comanip.planning.terms import Curvature

WITNESS_STEPS = 3
"""Damped least-squares steps from a nearby joint position that may show a goal reachable without the full inverse
kinematics (:meth:`Arm.goal_joints`); how close each step lands:
studies/how_many_steps_does_the_arm_reachability_witness_need/."""


class BodyKind(ABC):
    """The choices of one kind of body (module docstring), for one model."""

    name: str
    """'point mass' or 'arm'."""

    def __init__(self, model: ReachingModel):
        self.model = model

    @abstractmethod
    def check(self, options: SolverOptions) -> None:
        """ValueError when the model or the options ask for what this kind does not support."""

    @abstractmethod
    def iteration_limit(self, options: SolverOptions) -> int:
        """The iteration limit per start: ``options.max_iterations``, else this kind's default."""

    @abstractmethod
    def tolerance(self, options: SolverOptions) -> float:
        """The convergence tolerance on the gradient of the normalised objective."""

    @abstractmethod
    def curvature(self, problem: ReachProblem, options: SolverOptions) -> Curvature:
        """The Newton method's objective, gradient and Hessian terms."""

    @abstractmethod
    def compiles_after_solving(self, options: SolverOptions) -> bool:
        """Whether the terms compile in the background once the planner has solved ``compile_after`` seconds."""

    @abstractmethod
    def start_policy(self, options: SolverOptions, problem: ReachProblem, solver: ReachSolver) -> StartPolicy:
        """Where the planner's solves start."""

    @abstractmethod
    def goal_joints(self, params: ReachParameters, near: np.ndarray | None = None) -> np.ndarray | None:
        """A joint position (n,) within the limits whose end effector lies within the goal width of the goal if any
        does (the reachability witness of a solve of the reach ``params``); None where every goal is reachable."""


class PointMass(BodyKind):
    """A linear body (module docstring)."""

    name = "point mass"

    def check(self, options: SolverOptions) -> None:
        """Everything is supported."""

    def iteration_limit(self, options: SolverOptions) -> int:
        return options.max_iterations if options.max_iterations is not None else options.point_mass_iterations

    def tolerance(self, options: SolverOptions) -> float:
        return options.tolerance

    def curvature(self, problem: ReachProblem, options: SolverOptions) -> Curvature:
        return ReachCurvature(problem, compile=options.compile)

    def compiles_after_solving(self, options: SolverOptions) -> bool:
        return options.compile is None

    def start_policy(self, options: SolverOptions, problem: ReachProblem, solver: ReachSolver) -> StartPolicy:
        return PointMassStarts(self.model, options, problem, solver)

    def goal_joints(self, params: ReachParameters, near: np.ndarray | None = None) -> None:
        return None


class Arm(BodyKind):
    """A nonlinear body (module docstring)."""

    name = "arm"

    def check(self, options: SolverOptions) -> None:
        model = self.model
        if model.activation:
            raise ValueError(f"activation stages are supported for point-mass bodies; the {model.body.name!r} "
                             f"body needs activation=()")
        if options.method == "ipopt":
            raise ValueError(f"method 'ipopt' (exact Hessian of the expanded problem) is for point masses; the "
                             f"{model.body.name!r} body needs method 'newton'")

    def iteration_limit(self, options: SolverOptions) -> int:
        return options.max_iterations if options.max_iterations is not None else options.arm_iterations

    def tolerance(self, options: SolverOptions) -> float:
        return options.tolerance if options.arm_tolerance is None else options.arm_tolerance

    def curvature(self, problem: ReachProblem, options: SolverOptions) -> Curvature:
        return LinearisedCurvature(problem, compile=options.compile is not False)

    def compiles_after_solving(self, options: SolverOptions) -> bool:
        return False

    def start_policy(self, options: SolverOptions, problem: ReachProblem, solver: ReachSolver) -> StartPolicy:
        return ArmStarts(self.model, options, problem, solver)

    def goal_joints(self, params: ReachParameters, near: np.ndarray | None = None) -> np.ndarray:
        """Without ``near``: the inverse kinematics from the start (a cold solve's guesses reach for it). With a joint
        position ``near`` (n,), e.g. the final mean position of a plan to a nearby goal: ``WITNESS_STEPS`` damped
        least-squares steps from it (clipped to the limits), far cheaper, when they bring the hand within w of the
        goal (a goal moved by a few cm: they do), else the inverse kinematics from ``near``."""
        body, goal = self.model.body, params.goal
        if near is None:
            return body.inverse_kinematics(goal, params.start[: self.model.n])
        witness = body.clip_to_limits(body.least_squares_inverse_kinematics(goal, near, WITNESS_STEPS))
        return witness if end_effector_distance(body, witness, goal) <= params.width else body.inverse_kinematics(goal, near)


def body_kind(model: ReachingModel) -> BodyKind:
    """The kind of the model's body: :class:`PointMass` for a linear body, else :class:`Arm`."""
    return PointMass(model) if model.body.is_linear else Arm(model)


def end_effector_distance(body, q: np.ndarray, point: np.ndarray) -> float:
    """Distance (m) of the body's end effector at joint position q (n,) from a point (d,)."""
    return float(np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - point))
