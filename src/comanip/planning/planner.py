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
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from comanip.arguments import as_bounded_vector, as_count, as_goal_width, as_optional_positive, as_position, as_positive
from comanip.model import ReachingModel
from comanip.plausibility import with_plausibility_warnings
from comanip.optim import Evaluation
from comanip.planning.ipopt_reach_solver import IpoptReachSolver
from comanip.planning.newton_reach_solver import NewtonReachSolver
from comanip.planning.path_limits import PathLimits
from comanip.planning.plan import Plan, PlanStatus, with_reach_check
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver, rank
from comanip.planning.single_thread_blas import SingleThreadBlas
from comanip.planning.starts import StartPolicy
from comanip.planning.terms import Curvature

SOLVER_METHODS = ("newton", "ipopt")
COLD_SEARCHES = ("ranked", "all")
WITNESS_STEPS = 3
"""Damped least-squares steps from a warm-start plan's final position that may show a goal reachable without the
full inverse kinematics (:meth:`Planner._goal_joints`); how close each step lands:
studies/how_many_steps_does_the_arm_reachability_witness_need/."""


@dataclass(frozen=True)
class SolverOptions:
    """How the planner's NLP is solved."""

    method: str = "newton"
    """'newton' (damped Newton on the structure-exploiting Hessian, fast) or 'ipopt' (IPOPT with CasADi's
    exact Hessian, the reference)."""
    max_iterations: int | None = None
    """Iteration limit per start (Newton: Hessian evaluations; IPOPT: its iterations). None:
    ``point_mass_iterations`` for point masses, ``arm_iterations`` for nonlinear bodies."""
    point_mass_iterations: int = 200
    """The iteration limit for point masses when ``max_iterations`` is None (exact Hessian: Newton converges
    quadratically)."""
    arm_iterations: int = 1000
    """The iteration limit for nonlinear bodies when ``max_iterations`` is None (approximate Hessian: linear
    convergence)."""
    tolerance: float = 1e-8
    """Convergence tolerance on the gradient of the normalised objective (J divided by the goal's peak reward
    times the sum of discount weights, so it lies in about [-1, 0]); IPOPT's ``tol``. For nonlinear bodies
    ``arm_tolerance`` applies instead, unless it is None."""
    arm_tolerance: float | None = 1e-6
    """The convergence tolerance for nonlinear bodies (None: ``tolerance``). Their approximate Hessian converges
    linearly, and the iterations from 1e-6 to 1e-8 only polish the gradient; a looser tolerance stops the paper's
    ``franka`` plans early on their flat valley (studies/which_newton_options_suit_the_arm/)."""
    hessian_refresh: int = 3
    """Nonlinear bodies: the approximate Hessian is assembled every this many Newton iterations, and after any step
    the line search shortened or taken with a limit in the working set; in between it is kept with its secant
    corrections updated (:func:`comanip.optim.active_set_newton.newton_minimize`). 1: every iteration. Point masses (exact
    Hessian) assemble theirs as before whatever this says (the trade: studies/which_newton_options_suit_the_arm/)."""
    n_starts: int = 3
    """Minimum-jerk initial guesses of a cold solve (durations spread over the horizon). A warm-started
    solve uses the warm start only."""
    cold_search: str = "ranked"
    """How a cold solve starts. 'all': from each of the ``n_starts`` minimum-jerk guesses, keeping the best
    converged plan. 'ranked': from the lowest-objective start among those guesses and, for a point mass, a solved
    reach turned to the goal (past ``narrow_ratio`` widths: the library's plans near each local optimum), for an arm
    at its ready pose, the nearest plans of its reach library
    (:meth:`StartPolicy.cold_starts <comanip.planning.starts.StartPolicy.cold_starts>`), about as fast as a warm
    solve, with every guess solved where a moving hand's local optima compete (point masses) or the guesses as
    fallbacks (arms). An arm
    without a library, or away from its ready pose, runs every guess as 'all' does, except from rest the one of
    highest objective for a goal beyond ``arm_narrow_ratio`` widths. benchmarks/cold_quality.py
    compares 'ranked' with 'all' under the cold-search rule (docs/results/speed.md)."""
    narrow_ratio: float = 20.0
    """Reach distance over goal width beyond which local optima compete in a point mass's 'ranked' cold solve: it
    starts from the reach library's plans near each of them (:meth:`ReachLibrary.local_optima
    <comanip.planning.starts.reach_library.ReachLibrary.local_optima>`) instead of the nearest solved reach, or,
    from a start whose motion carries the hand on, solves from every minimum-jerk guess. The distance counts from
    the start and from where a stop of its motion ends. Far, narrow goals of the planar preset have several local
    optima (the lowest-objective minimum-jerk start ended 0.7 % worse on 1 of 200 random problems, at 54 widths;
    none below 20 widths on any point-mass preset)."""
    arm_narrow_ratio: float = 4.0
    """Reach distance over goal width beyond which an arm's 'ranked' cold search from rest without a reach library
    leaves out its minimum-jerk guess of highest objective: there that start seldom ends best and is the slowest to
    converge (it lies near the zero-reward plateau). Nearer or wider goals, and moving starts, run every guess
    (studies/may_an_arm_cold_search_leave_out_its_worst_guess/)."""
    far_warm_start: float = 3.0
    """Goal widths: a warm start (a plan to another goal) whose final hand position is farther than this
    from the new goal lies where the goal's reward underflows, so ``n_starts`` fresh reaches compete with it. For
    a plan that carries its goal sensitivity the position is where the predicted start ends."""
    arm_library: str | None = None
    """An arm's reach library for 'ranked' cold solves from its ready pose, at rest or moving (its nearest plan
    also competes with a warm start there): a file written by ``comanip library`` (.npz) for this model. None:
    the library shipped for the model (``franka_rest``), if any (:mod:`comanip.planning.starts.arm_reach_library`)."""
    abandon_after: int = 80
    """Newton iterations after which a 'ranked' cold search that runs every start (an arm without a reach library, a
    point mass's narrow goal) abandons a start that has not converged, when a start that has converged within the
    limits by then has a lower objective than it has there: on the Panda long starts crawl along a joint limit and
    seldom end best (studies/may_an_arm_cold_search_abandon_long_starts/); 'all' runs every start to the end."""
    threads: int | None = None
    """Threads that solve a nonlinear body's cold starts side by side when every start is solved (an arm without a
    reach library, or ``cold_search="all"``): a Newton iteration on an arm spends most of its time in
    compiled code and LAPACK, which run outside Python's interpreter lock (:mod:`comanip.planning.start_threads`).
    None: one thread per start, at most one per processor the process may use; 1: one start after another (e.g.
    for sweeps that already run a process per core). The plan is the same whatever this says: each start is solved
    alone and the best is kept by the same rule."""
    ipopt: dict = field(default_factory=dict)
    """Extra IPOPT options, passed through (e.g. {"hessian_approximation": "limited-memory"})."""
    compile: bool | None = None
    """Compile the Newton method's per-solve function to C (cached on disk, see comanip.caching.compiled).
    True: when the planner is built. False: never. None: when built for nonlinear bodies, where CasADi's
    virtual machine is ten times slower (a first build takes a minute or two for the Panda); for a point mass,
    in a background thread once the planner has spent ``compile_after`` seconds solving, its solves going on
    uncompiled meanwhile: compiling costs 3–17 s for every new model, which short-lived planners (a fit's,
    one per parameter set) would not win back, while a long-lived one (a control loop, a sweep) solves
    faster afterwards (docs/results/speed.md). A model compiled before (by any planner, in any
    process, with this version of the package) is loaded compiled from the disk cache when built."""
    compile_after: float = 2.0
    """Seconds of solving (the sum of ``plan.solve_time``) after which a point-mass planner with ``compile=None``
    compiles its per-solve function in the background."""

    def __post_init__(self):
        if self.method not in SOLVER_METHODS:
            raise ValueError(f"method must be one of {SOLVER_METHODS}, got {self.method!r}")
        as_count("max_iterations", self.max_iterations, optional=True)
        as_count("threads", self.threads, optional=True)
        for name in ("n_starts", "point_mass_iterations", "arm_iterations", "hessian_refresh", "abandon_after"):
            as_count(name, getattr(self, name))
        as_positive("far_warm_start", self.far_warm_start, "goal widths")
        as_positive("narrow_ratio", self.narrow_ratio, "reach distance over goal width")
        as_positive("arm_narrow_ratio", self.arm_narrow_ratio, "reach distance over goal width")
        as_positive("compile_after", self.compile_after, "s of solving")
        if self.cold_search not in COLD_SEARCHES:
            raise ValueError(f"cold_search must be one of {COLD_SEARCHES}, got {self.cold_search!r}")
        as_positive("tolerance", self.tolerance, "gradient of the normalised objective")
        if self.arm_tolerance is not None:
            as_positive("arm_tolerance", self.arm_tolerance, "gradient of the normalised objective")
        if self.compile not in (None, True, False):
            raise ValueError(f"compile must be None, True or False, got {self.compile!r}")


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
        if not model.body.is_linear and model.activation:
            raise ValueError(f"activation stages are supported for point-mass bodies; the {model.body.name!r} "
                             f"body needs activation=()")
        if self.options.method == "ipopt" and not model.body.is_linear:
            raise ValueError(f"method 'ipopt' (exact Hessian of the expanded problem) is for point masses; the "
                             f"{model.body.name!r} body needs method 'newton'")
        self._build()

    def _build(self) -> None:
        problem = self.problem = ReachProblem(self.model)
        limits, blas = PathLimits.of(self.model), SingleThreadBlas()
        self.solver: ReachSolver = NewtonReachSolver(problem, self.options, blas, limits) \
            if self.options.method == "newton" else IpoptReachSolver(problem, self.options, blas)
        """How each solve runs from its starts (:class:`~comanip.planning.reach_solver.ReachSolver`), chosen by
        ``SolverOptions.method``."""
        self.starts = StartPolicy(self.model, self.options, problem, self.solver)
        """Where each solve starts (:class:`~comanip.planning.starts.StartPolicy`)."""

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
        goal_q = None if self.model.body.is_linear else self._goal_joints(start, goal, width, warm_start)
        unreachable = self._unreachable_plan(params, goal_q, t_begin)
        if unreachable is not None:
            return unreachable
        with self.solver.blas:  # the starts' small products too: one BLAS switch per solve
            guesses = self.starts.guesses(params, warm_start, budgeted=max_wall_time is not None,
                                          goal_q=goal_q if warm_start is None else None)
            from_library = warm_start is None and self.starts.from_arm_library(start)
            plan = with_reach_check(self._solve_from(guesses, params, t_begin, max_wall_time, until_converged=from_library))
        self.solver.count_solving_time(plan.solve_time)
        return with_plausibility_warnings(self.model, plan)  # a point mass is a person's hand: name implausible reaches

    def _goal_joints(self, start, goal, width, warm_start) -> np.ndarray:
        """An arm's joint position (n,) within its joint limits that puts the hand within the goal width w of the
        goal if any does (the reachability witness of :meth:`_unreachable_plan`).

        A cold solve: the inverse kinematics from the start (its guesses reach for it). A warm start from a plan:
        ``WITNESS_STEPS`` damped least-squares steps (clipped to the limits) from the plan's final mean position,
        far cheaper, when they bring the hand within w of the goal (a warm
        solve to a goal moved by a few cm: they do), else the inverse kinematics from that position."""
        model, body = self.model, self.model.body
        if not (isinstance(warm_start, Plan) and warm_start.mean.shape == (model.H + 1, model.state_size)):
            return body.inverse_kinematics(goal, start[: model.n])
        final = warm_start.mean[-1, : model.n]
        near = body.clip_to_limits(body.least_squares_inverse_kinematics(goal, final, WITNESS_STEPS))
        return near if _distance(body, near, goal) <= width else body.inverse_kinematics(goal, final)

    def _unreachable_plan(self, params: ReachParameters, goal_q: np.ndarray | None, t_begin: float) -> Plan | None:
        """A plan with status 'unreachable' when no joint position within the limits puts the end effector
        within the goal width of the goal (the residual of ``goal_q`` (n,), :meth:`_goal_joints`, > w); None
        otherwise, and for point masses (``goal_q`` None: they reach everywhere). An arm is checked before any
        solver work."""
        model, body, goal, width = self.model, self.model.body, params.goal, params.width
        if goal_q is None:
            return None
        residual = _distance(body, goal_q, goal)
        if residual <= width:
            return None
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


def _distance(body, q: np.ndarray, point: np.ndarray) -> float:
    """Distance (m) of the body's end effector at joint position q (n,) from a point (d,)."""
    return float(np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - point))


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
