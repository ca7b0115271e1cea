"""How the planner solves a reach from the starts it is given: the :class:`ReachSolver` strategy.

The planner picks one strategy when it is built (``SolverOptions.method``): the Newton method on the
structure-exploiting Hessian (:class:`~comanip.planning.newton_reach_solver.NewtonReachSolver`) or IPOPT, the
reference (:class:`~comanip.planning.ipopt_reach_solver.IpoptReachSolver`). The start policy and a point mass's
reach library rank and solve their starts through the same public interface.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from comanip.optim import Evaluation, LocalModel, SolverResult, Status
from comanip.planning.plan import Plan
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.single_thread_blas import SingleThreadBlas
from comanip.planning.solver_options import SolverOptions
from comanip.planning.terms import Curvature

if TYPE_CHECKING:
    from comanip.planning.goal_sensitivity import GoalSensitivity


class Rank(NamedTuple):
    """Where a start or a solve's result stands among others (the lowest is the best): within the limits first, then
    the lower objective."""

    beyond_limits: bool
    objective: float


def rank(result: SolverResult) -> Rank:
    """The rank of a solve's result: its status 'constraints_violated', its normalised objective."""
    return Rank(result.status == Status.CONSTRAINTS_VIOLATED, result.fun)


class ReachSolver(ABC):
    """Solves the reach problem from given starts (torques (H, n)), each result's x the torques (H, n) and fun the
    objective normalised by |J_best(w)|.

    Args:
        problem: the reach problem; options: the planner's ``SolverOptions``; blas: the planner's one-thread BLAS
            context, in which every solve runs; max_iterations: the iteration limit per start (the body kind's,
            :meth:`BodyKind.iteration_limit <comanip.planning.body_kind.BodyKind.iteration_limit>`).
    """

    curvature: Curvature | None = None
    """The Newton method's objective, gradient and Hessian terms; None where the strategy has none."""

    def __init__(self, problem: ReachProblem, options: SolverOptions, blas: SingleThreadBlas, max_iterations: int):
        self.problem, self.options, self.blas = problem, options, blas
        self.max_iterations = max_iterations

    @abstractmethod
    def run(self, guess: np.ndarray, params: ReachParameters, deadline: float) -> SolverResult[np.ndarray, LocalModel]:
        """One solve from torques ``guess`` (H, n) until ``deadline`` (perf_counter, s), as the solver returns it."""

    @abstractmethod
    def objective(self, torque: np.ndarray, params: ReachParameters) -> float:
        """J, or J normalised (for comparisons at fixed parameters), of torques (H, n)."""

    @abstractmethod
    def ends_at_goal(self, torque: np.ndarray, params: ReachParameters) -> bool:
        """True when the mean end effector of torques (H, n) ends within the goal width of the goal (a converged
        plan can rest on the zero-reward plateau instead)."""

    def start_rank(self, torque: np.ndarray, params: ReachParameters) -> Rank:
        """The rank of a start (H, n) among candidate starts: its mean path beyond a joint limit, its objective."""
        return Rank(False, self.objective(torque, params))

    def solve(self, guess: np.ndarray, params: ReachParameters, deadline: float = np.inf) -> SolverResult[np.ndarray, LocalModel]:
        """One solve from torques ``guess`` (H, n) until ``deadline`` (perf_counter, s); a non-finite plan comes back
        as the guess with status 'failed'."""
        return self.finite(self.run(guess, params, deadline), guess, params)

    def results(self, guesses: list[np.ndarray], params: ReachParameters, deadline: float = np.inf,
                until_converged: bool = False) -> list[SolverResult[np.ndarray, LocalModel]]:
        """One result per guess solved (each (H, n)), until the deadline has passed (after the first): several
        guesses as the strategy's cold search (:meth:`search`); ``until_converged``: in turn, stopping at the first
        whose solve converges ('solved') and ends at the goal (later guesses are fallbacks)."""
        with self.blas:
            if until_converged or len(guesses) == 1:
                return self.in_turn(guesses, params, deadline, until_converged)
            return self.search(guesses, params, deadline)

    def search(self, guesses: list[np.ndarray], params: ReachParameters, deadline: float) -> list[SolverResult[np.ndarray, LocalModel]]:
        """Every guess's solve (each (H, n)), one after another."""
        return self.in_turn(guesses, params, deadline, until_converged=False)

    def in_turn(self, guesses: list[np.ndarray], params: ReachParameters, deadline: float,
                until_converged: bool) -> list[SolverResult[np.ndarray, LocalModel]]:
        """The guesses' solves one after another, each to convergence, until the deadline has passed (after the
        first) or, ``until_converged``, the best so far is 'solved' and ends at the goal."""
        results = []
        for guess in guesses:
            if results and time.perf_counter() > deadline:
                break
            results.append(self.solve(guess, params, deadline))
            best = min(results, key=rank)
            if until_converged and best.status == Status.SOLVED and self.ends_at_goal(best.x, params):
                break
        return results

    def finite(self, result: SolverResult, guess: np.ndarray, params: ReachParameters) -> SolverResult:
        """The result, or, where the solver returned a non-finite plan, the guess (H, n) with status 'failed'."""
        if np.isfinite(result.x).all() and np.isfinite(result.fun):
            return result
        problem = self.problem
        objective = problem.objective_value(guess, params.start, params.goal, params.width) / problem.normaliser(params.width)
        return SolverResult(guess, objective, Status.FAILED, "solver returned a non-finite plan; returning the initial guess",
                            result.nit, np.inf)

    def make_plan(self, torque: np.ndarray, params: ReachParameters, evaluation: Evaluation | None = None, **fields) -> Plan:
        """The Plan of torques (H, n); ``evaluation``: the solver's own evaluation at them, where it has one."""
        return self.problem.make_plan(torque, params, **fields)

    def sensitivity(self, result: SolverResult) -> GoalSensitivity | None:
        """How the torques of a solve's plan move with the goal, where the strategy knows (None otherwise)."""
        return None

    def count_solving_time(self, seconds: float) -> None:
        """Told the time of each solve (s), for strategies that change once the planner has solved a while."""
