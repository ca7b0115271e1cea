"""The reaching planner: the belief-space optimal control problem, built once and solved many times.

    minimise over tau_{0:H-1}   J = Σ_{i=0..H} -w_i R(mu_i, Sigma_i; g, W(w)) + nu Σ ||tau_i||²
    subject to                  mu_0 = s_0, Sigma_0 = 0, and the belief dynamics of docs/formulation.md §2,
                                |tau_i| ≤ tau_max and the joint limits on the mean (bodies that have them).

Single shooting: the torques are the only decision variables and mu, Sigma are CasADi expressions of
them, so Sigma stays positive semi-definite at every iterate (multiple shooting over Sigma lets iterates go
indefinite, docs/formulation.md §9). Start state, goal and width are parameters, so one build serves every solve.

Two solver strategies (``SolverOptions.method``, chosen when the planner is built: ``planner.solver``, a
:class:`~comanip.planning.reach_solver.ReachSolver`); the start policy (``planner.starts``) proposes the starts and
the strategy solves them:

- ``newton`` (default, :class:`~comanip.planning.newton_reach_solver.NewtonReachSolver`): a regularised Newton
  method with an active set for the limits (:mod:`comanip.optim.active_set_newton`) on a Hessian assembled from
  per-step pieces: exact for point masses (:mod:`comanip.planning.curvature`), approximate with secant corrections
  for nonlinear bodies (:mod:`comanip.planning.linearised_curvature`, compiled to C on first use and cached on disk).
  Several times faster than IPOPT on the point masses, to the same optimum (docs/results/speed.md).
- ``ipopt`` (:class:`~comanip.planning.ipopt_reach_solver.IpoptReachSolver`): IPOPT with CasADi's exact Hessian
  of the whole single-shooting problem: the reference, point masses only.

Goals out of an arm's reach (inverse-kinematics residual beyond the goal width) return a plan with
status 'unreachable' before any solver work.

Both minimise the same objective, normalised by |J_best(w)| (the best attainable J) so that tolerances
mean the same for every width; ``plan.objective`` is always the docs/formulation.md §4 J itself.

Symbols, shapes and units: ``docs/notation.md``.
"""

from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np

from comanip.arguments import as_bounded_vector, as_goal_width, as_optional_positive, as_position
from comanip.model import ReachingModel
from comanip.plausibility import with_plausibility_warnings
from comanip.optim import Evaluation
from comanip.planning.body_kind import body_kind, end_effector_distance
from comanip.planning.ipopt_reach_solver import IpoptReachSolver
from comanip.planning.newton_reach_solver import NewtonReachSolver
from comanip.planning.path_limits import PathLimits
from comanip.planning.plan import Plan, PlanStatus, with_reach_check
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver, rank
from comanip.planning.single_thread_blas import SingleThreadBlas
from comanip.planning.solver_options import SolverOptions
from comanip.planning.starts.start_policy import StartPolicy
from comanip.planning.terms import Curvature

class Planner:
    """Plans reaches for one :class:`ReachingModel`; build once, then call :meth:`solve` many times.

    >>> planner = Planner(comanip.presets.planar())
    >>> plan = planner.solve(start=np.zeros(4), goal=[0.3, 0.0], width=0.02)
    >>> again = planner.solve(np.zeros(4), [0.3, 0.05], 0.02, warm_start=plan)
    """

    def __init__(self, model: ReachingModel, options: SolverOptions | None = None):
        if not isinstance(model, ReachingModel):
            raise ValueError(f"model must be a comanip.ReachingModel (e.g. comanip.presets.planar()), got {type(model).__name__}")
        self.model = model
        self.options = options or SolverOptions()
        self.kind = body_kind(model)
        """What planning does for this kind of body (:class:`~comanip.planning.body_kind.BodyKind`), chosen once."""
        self.kind.check(self.options)
        self._build()

    def _build(self) -> None:
        problem = self.problem = ReachProblem(self.model)
        kind, options = self.kind, self.options
        blas, limit = SingleThreadBlas(), kind.iteration_limit(options)
        self.solver: ReachSolver = NewtonReachSolver(
            problem, options, blas, limit, PathLimits.of(self.model), kind.curvature(problem, options),
            kind.tolerance(options), kind.compiles_after_solving(options)) \
            if options.method == "newton" else IpoptReachSolver(problem, options, blas, limit)
        """How each solve runs from its starts (:class:`~comanip.planning.reach_solver.ReachSolver`), chosen by
        ``SolverOptions.method``."""
        self.starts: StartPolicy = kind.start_policy(options, problem, self.solver)
        """Where each solve starts (:class:`~comanip.planning.starts.StartPolicy`, the body kind's)."""

    @property
    def curvature(self) -> Curvature | None:
        """The Newton method's objective, gradient and Hessian terms (None for ``method="ipopt"``); the goal
        estimator reuses them."""
        return self.solver.curvature

    def check_inputs(self, start, goal, width) -> ReachInputs:
        """Validated start (nx,), goal (d,) and width, or ValueError naming the argument (:func:`reach_inputs`)."""
        return reach_inputs(self.model, start, goal, width)

    def solve(self, start, goal, width: float | None = None, warm_start=None, max_wall_time: float | None = None) -> Plan:
        """Plan a reach.

        Args:
            start: start state s_0 = [q; qdot] (2n,), m and m/s (rad, rad/s for joints); a model with activation
                stages also takes the full state (nx,), else they start at zero force.
            goal: goal position (d,), m, in task space.
            width: goal width w (m) > 0; the model's default when None.
            warm_start: a previous :class:`Plan` or torques (H, n) to start from; cold multi-start when None. A
                plan for another goal starts the solve from the best of itself and itself moved onto the goal:
                for a point-mass plan this planner solved, from the same start at the same width, by the optimum's
                first-order sensitivity to the goal (``plan.goal_sensitivity``); otherwise by joint-space
                minimum-jerk corrections. From an arm reach library's ready pose the library's nearest plan, moved
                onto the goal (and braked, from a moving start), competes too.
            max_wall_time: wall-time budget (s) for the whole solve; the best plan so far is returned with
                status 'max_wall_time' when it runs out. A budgeted cold solve starts only from reach-library
                entries solved before (:meth:`StartPolicy.cold_starts <comanip.planning.starts.StartPolicy.cold_starts>`): a new one would be a whole solve outside the budget.

        Returns:
            A :class:`Plan`; never raises on a failed solve (check ``plan.success``: converged and reaching). For a
            point mass, a reach no person makes (too far, too fast) keeps its status and gets a warning in its
            message and ``extras['warnings']`` (:mod:`comanip.plausibility`).
        """
        start, goal, width = self.check_inputs(start, goal, width)
        max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")
        t_begin = time.perf_counter()
        params = ReachParameters(start, goal, width)
        goal_q = self.goal_joints(params, self._final_position(warm_start))
        unreachable = self._unreachable_plan(params, goal_q, t_begin)
        if unreachable is not None:
            return unreachable
        with self.solver.blas:  # the starts' small products too: one BLAS switch per solve
            if warm_start is None and max_wall_time is None:  # a new library entry is a whole cold search: not on a budget
                self.starts.fill_library(params)
            guesses = self.starts.guesses(params, warm_start, goal_q=goal_q if warm_start is None else None)
            from_library = warm_start is None and self.starts.from_arm_library(start)
            plan = with_reach_check(self._solve_from(guesses, params, t_begin, max_wall_time, until_converged=from_library))
        self.solver.count_solving_time(plan.solve_time)
        return with_plausibility_warnings(self.model, plan)  # a point mass is a person's hand: name implausible reaches

    def goal_joints(self, params: ReachParameters, near: np.ndarray | None = None) -> np.ndarray | None:
        """An arm's joint position (n,) within its joint limits that puts the hand within the goal width of the goal if
        any does, the reachability witness of a solve of the reach ``params``, searched from the joint position
        ``near`` (n,) when given (:meth:`Arm.goal_joints <comanip.planning.body_kind.Arm.goal_joints>`); None for a
        point mass, which reaches every goal."""
        return self.kind.goal_joints(params, near)

    def reaches(self, goal_q: np.ndarray, params: ReachParameters) -> bool:
        """Whether the end effector at joint position ``goal_q`` (n,) lies within the goal width of the goal of the
        reach ``params``."""
        return end_effector_distance(self.model.body, goal_q, params.goal) <= params.width

    def _final_position(self, warm_start) -> np.ndarray | None:
        """The final mean joint position (n,) of a warm-start plan of this model, None for any other warm start."""
        model = self.model
        if isinstance(warm_start, Plan) and warm_start.mean.shape == (model.H + 1, model.state_size):
            return warm_start.mean[-1, : model.n]
        return None

    def _unreachable_plan(self, params: ReachParameters, goal_q: np.ndarray | None, t_begin: float) -> Plan | None:
        """A plan with status 'unreachable' when no joint position within the limits puts the end effector
        within the goal width of the goal (the residual of ``goal_q`` (n,), :meth:`goal_joints`, > w); None
        otherwise, and for point masses (``goal_q`` None: they reach everywhere). An arm is checked before any
        solver work."""
        model, body, goal, width = self.model, self.model.body, params.goal, params.width
        if goal_q is None:
            return None
        if self.reaches(goal_q, params):
            return None
        residual = end_effector_distance(body, goal_q, goal)
        message = (f"goal {np.round(goal, 4).tolist()} m is {residual:.3f} m from the nearest point the {body.name} reaches "
                   f"within its joint limits, beyond the goal width {width} m; no plan was solved (the arm holds still)")
        torque = np.zeros((model.H, model.n))
        return self.solver.make_plan(torque, params, status=PlanStatus.UNREACHABLE, success=False, message=message,
                                     solve_time=time.perf_counter() - t_begin, iterations=0)

    def _solve_from(self, guesses, params: ReachParameters, t_begin: float, max_wall_time: float | None,
                    until_converged: bool = False) -> Plan:
        """The best plan from the guesses (each (H, n)), solved by the planner's strategy
        (:meth:`ReachSolver.results <comanip.planning.reach_solver.ReachSolver.results>`). ``until_converged``: stop at the first whose solve converges
        ('solved') within the limits and ends at the goal (later guesses are fallbacks). A solve that stalled
        ('solved_acceptable', along a redundant arm's flat directions) does not stop the search: on 200 cold
        franka_rest problems 5 library starts did, one of them 6.4e-6 above the plan of the full search
        (benchmarks/cold_quality.py, problem 175)."""
        deadline = np.inf if max_wall_time is None else t_begin + max_wall_time
        solver = self.solver
        results = solver.results(guesses, params, deadline, until_converged)
        # The plan within the limits with the lowest objective wins, whatever its status: a start that stalls short
        # of the tolerances can still be far better than one that converged on the zero-reward plateau (seen on the
        # Panda), and the status then says it did not converge.
        best = min(results, key=rank)
        evaluation = None if best.local_model is None else Evaluation(best.fun, None, best.local_model.data)
        plan = solver.make_plan(best.x, params, evaluation, status=best.status, success=best.success, message=best.message,
                                solve_time=time.perf_counter() - t_begin, iterations=sum(result.nit for result in results))
        plan.goal_sensitivity = solver.sensitivity(best)
        return plan


class ReachInputs(NamedTuple):
    """A reach's inputs, checked (:func:`reach_inputs`)."""

    start: np.ndarray
    """Start state (nx,)."""
    goal: np.ndarray
    """Goal (d,), m."""
    width: float
    """Goal width (m)."""


def reach_inputs(model: ReachingModel, start, goal, width) -> ReachInputs:
    """The checked start (nx,), goal (d,) and width (m) of a reach for ``model``, or ValueError naming the
    argument; no planner needed, so callers can check every input before building one.

    A start of [q; qdot] (2n,) for a model with activation stages gets them at zero force."""
    size = 2 * model.n if np.shape(start) == (2 * model.n,) else model.state_size
    start = model.full_state(as_bounded_vector("start", start, size, "state [q; qdot] in m and m/s, or rad and rad/s"
                                       + (f", optionally followed by the {model.state_size - 2 * model.n} activation states"
                                          if size != 2 * model.n else "")))
    goal = as_position("goal", goal, model.d)
    width = model.width if width is None else as_goal_width("width", width)
    return ReachInputs(start, goal, width)


def plan_reach(model: ReachingModel, start, goal, width: float | None = None, **solve_options) -> Plan:
    """One-off plan: builds a :class:`Planner` for the model and solves once. Reuse a Planner in loops."""
    return Planner(model).solve(start, goal, width, **solve_options)
