"""The planner's Newton strategy (:class:`NewtonReachSolver`): the active-set Newton method
(:mod:`comanip.optim.active_set_newton`) on a Hessian assembled from per-step pieces, exact for point masses
(:mod:`comanip.planning.curvature`), approximate with secant corrections for nonlinear bodies
(:mod:`comanip.planning.linearised_curvature`)."""

from __future__ import annotations

import time

import numpy as np

from comanip.optim import CONVERGED, Evaluation, LocalModel, NewtonSolve, SolverResult
from comanip.optim.active_set_newton import newton_solve
from comanip.optim.hessian_models import PreparedHessian, prepare_hessian
from comanip.optim.newton_loop import never
from comanip.planning.goal_sensitivity import GoalSensitivity
from comanip.planning.linearised_curvature import LinearisedCurvature
from comanip.planning.path_limits import LIMIT_TOLERANCE, PathLimits
from comanip.planning.plan import Plan
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import Rank, ReachSolver
from comanip.planning.single_thread_blas import SingleThreadBlas
from comanip.planning.start_threads import StartThreads, usable_cores
from comanip.planning.terms import Curvature


class NewtonReachSolver(ReachSolver):
    """The Newton method on the reach problem's own Hessian terms (:attr:`curvature`).

    Args:
        problem, options, blas, max_iterations: as for :class:`~comanip.planning.reach_solver.ReachSolver`; limits: the
            joint limits on the mean path; curvature: the terms (the body kind's); tolerance: the convergence tolerance
            on the gradient of the normalised objective; compiles_after_solving: compile the terms in the background
            once the planner has solved ``options.compile_after`` seconds.
    """

    def __init__(self, problem: ReachProblem, options, blas: SingleThreadBlas, max_iterations: int, limits: PathLimits,
                 curvature: Curvature, tolerance: float, compiles_after_solving: bool = False):
        super().__init__(problem, options, blas, max_iterations)
        model = problem.model
        self.limits, self.curvature, self.tolerance = limits, curvature, tolerance
        self.torque_bounds = (np.tile(-model.body.tau_max, model.H), np.tile(model.body.tau_max, model.H))
        self._solving_time = 0.0 if compiles_after_solving else None
        threads = min(options.n_starts, usable_cores()) if options.threads is None else options.threads
        self._start_threads = StartThreads(self.curvature, threads) \
            if threads > 1 and isinstance(self.curvature, LinearisedCurvature) else None

    def run(self, guess: np.ndarray, params: ReachParameters, deadline: float) -> SolverResult[np.ndarray, LocalModel]:
        return self._as_torques(self.newton_solve(guess, params, deadline, self.curvature).advance(self.max_iterations))

    def newton_solve(self, guess: np.ndarray, params: ReachParameters, deadline: float, curvature: Curvature,
                     prepared: PreparedHessian | None = None) -> NewtonSolve:
        """The Newton method's solve from torques guess (H, n) until ``deadline`` (perf_counter, s), evaluated with
        ``curvature`` (these terms or a start's own copy of them), to run in stages; its first step with the
        ``prepared`` Hessian (:meth:`prepared_hessian`) where one is given."""
        def value(x):  # line-search trials value-only: for either kind of body a fraction of an evaluation
            return curvature.value_and_data(x, params)

        return newton_solve(lambda x: curvature.evaluate(x, params), curvature.hessian, np.ravel(guess),
                            *self.torque_bounds, tolerance=self.tolerance, secant=not curvature.exact,
                            hessian_refresh=1 if curvature.exact else self.options.hessian_refresh,
                            constraints=self.limits.for_newton(curvature) if self.limits.active else None,
                            constraint_tolerance=LIMIT_TOLERANCE, value=value, prepared=prepared,
                            expired=(lambda: time.perf_counter() > deadline) if deadline < np.inf else never)

    def prepared_hessian(self, guess: np.ndarray, params: ReachParameters) -> PreparedHessian | None:
        """The Hessian of the normalised objective at torques guess (H, n) for ``params``, assembled and factored
        for a later solve from near there (None where it has no factor: a guess where the objective is not finite)."""
        curvature = self.curvature
        return prepare_hessian(curvature.hessian(curvature.evaluate(np.ravel(guess), params).data))

    def search(self, guesses: list[np.ndarray], params: ReachParameters, deadline: float) -> list[SolverResult[np.ndarray, LocalModel]]:
        """Every guess's solve, side by side on the start threads if there are any (``SolverOptions.threads``).
        'ranked' abandons a start that has not converged after ``abandon_after`` iterations when a start that has
        converged within the limits by then has a lower objective than it has there; 'all' runs every start to the
        end. The results do not depend on the threads: each start is solved alone, in the same two stages."""
        threads, options = self._start_threads, self.options
        terms = threads.terms(len(guesses)) if threads is not None else [self.curvature] * len(guesses)
        run = threads.map if threads is not None else _one_after_another
        budget = self.max_iterations
        checkpoint = min(budget, options.abandon_after) if options.cold_search == "ranked" else budget
        solves = [self.newton_solve(guess, params, deadline, curvature) for guess, curvature in zip(guesses, terms)]
        results = run(lambda solve: solve.advance(checkpoint), solves)
        lowest = min((result.fun for result in results if result.status in CONVERGED and result.violation <= LIMIT_TOLERANCE),
                     default=np.inf)
        going_on = [k for k, (solve, result) in enumerate(zip(solves, results)) if not solve.finished and not result.fun > lowest]
        for k, result in zip(going_on, run(lambda k: solves[k].advance(budget), going_on)):
            results[k] = result
        return [self.finite(self._as_torques(result), guess, params) for guess, result in zip(guesses, results)]

    def objective(self, torque: np.ndarray, params: ReachParameters) -> float:
        return self.curvature.value(np.ravel(torque), params)

    def start_rank(self, torque: np.ndarray, params: ReachParameters) -> Rank:
        """The rank of a start (H, n): its mean path beyond a joint limit, its objective. A start beyond the limits
        can have the lowest objective and still be the worst: the solver must first bring it back (on the Panda,
        starts retargeted far ended 'constraints_violated')."""
        curvature = self.curvature
        if not curvature.carries_belief or not self.limits.active:
            return Rank(False, self.objective(torque, params))
        evaluation = curvature.value_and_data(np.ravel(torque), params)
        return Rank(self.limits.violation(curvature.mean_path(evaluation.data)) > LIMIT_TOLERANCE, evaluation.f)

    def ends_at_goal(self, torque: np.ndarray, params: ReachParameters) -> bool:
        model, curvature = self.problem.model, self.curvature
        q_end = curvature.mean_path(curvature.value_and_data(np.ravel(torque), params).data)[-1, : model.n]
        end = np.asarray(model.body.kinematics_function(q_end)[0]).ravel()
        return bool(np.linalg.norm(end - params.goal) <= params.width)

    def make_plan(self, torque: np.ndarray, params: ReachParameters, evaluation: Evaluation | None = None, **fields) -> Plan:
        """The Plan of torques (H, n); an arm's belief is taken from ``evaluation`` (the Newton method's own f and
        data at them) without evaluating again."""
        curvature = self.curvature
        if not curvature.carries_belief:  # a point mass's expanded rollout is cheap
            return self.problem.make_plan(torque, params, **fields)
        evaluation = evaluation if evaluation is not None else curvature.evaluate(np.ravel(torque), params)
        return self.problem.make_plan(torque, params, belief=curvature.trajectory(evaluation.data),
                                      objective=evaluation.f * curvature.normaliser(params.width), **fields)

    def sensitivity(self, result: SolverResult) -> GoalSensitivity | None:
        """The goal sensitivity of a converged point-mass solve (from the last factorisation and the evaluation at
        the plan); None otherwise."""
        curvature = self.curvature
        if not curvature.exact or not result.success or result.local_model is None or result.local_model.factor is None:
            return None
        return GoalSensitivity(curvature, result.local_model.factor, result.local_model.data, self.blas)

    def count_solving_time(self, seconds: float) -> None:
        """Past ``compile_after`` seconds of solving, a point mass with ``compile=None`` compiles its terms in the
        background."""
        if self._solving_time is None:
            return
        self._solving_time += seconds
        if self._solving_time >= self.options.compile_after:
            self.curvature.compile_in_background()
            self._solving_time = None

    def _as_torques(self, result: SolverResult[np.ndarray, LocalModel]) -> SolverResult[np.ndarray, LocalModel]:
        """The result with x as torques (H, n)."""
        model = self.problem.model
        result.x = result.x.reshape(model.H, model.n)
        return result


def _one_after_another(function, items) -> list:
    """[function(item) for each item]: the start threads' ``map``, in the calling thread."""
    return [function(item) for item in items]
