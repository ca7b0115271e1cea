"""The reaching planner: the belief-space optimal control problem, built once and solved many times.

    minimise over tau_{0:H-1}   J = Σ_{i=0..H} -w_i R(mu_i, Sigma_i; g, W(w)) + nu Σ ||tau_i||²
    subject to                  mu_0 = s_0, Sigma_0 = 0, and the belief dynamics of docs/formulation.md §2,
                                |tau_i| ≤ tau_max and the joint limits on the mean (bodies that have them).

Single shooting: the torques are the only decision variables and mu, Sigma are CasADi expressions of
them, so Sigma stays positive semi-definite at every iterate (multiple shooting over Sigma lets iterates go
indefinite, docs/formulation.md §9). Start state, goal and width are parameters, so one build serves every solve.

Two solvers (``SolverOptions.method``):

- ``newton`` (default): a regularised Newton method with an active set for the limits
  (:mod:`comanip.optim.active_set_newton`) on a Hessian assembled from per-step pieces: exact for point masses
  (:mod:`comanip.planning.curvature`), approximate with secant corrections for nonlinear bodies
  (:mod:`comanip.planning.linearised_curvature`, compiled to C on first use and cached on disk).
  Several times faster than IPOPT on the point masses, to the same optimum (docs/results/speed.md).
- ``ipopt``: IPOPT with CasADi's exact Hessian of the whole single-shooting problem: the reference,
  point masses only.

Goals out of an arm's reach (inverse-kinematics residual beyond the goal width) return a plan with
status 'unreachable' before any solver work.

Both minimise the same objective, normalised by |J_best(w)| (the best attainable J) so that tolerances
mean the same for every width; ``plan.objective`` is always the docs/formulation.md §4 J itself.

Symbols, shapes and units: ``docs/notation.md``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from threadpoolctl import ThreadpoolController

from comanip.arguments import as_bounded_vector, as_count, as_goal_width, as_optional_positive, as_position, as_positive
from comanip.model import ReachingModel
from comanip.plausibility import with_plausibility_warnings
from comanip.planning.curvature import ReachCurvature
from comanip.optim import CONVERGED, Evaluation, LocalModel, NewtonSolve, SolverResult, Status
from comanip.planning.ipopt_status import IpoptDeadline, IpoptSolver, ipopt_status
from comanip.planning.goal_sensitivity import GoalSensitivity
from comanip.planning.linearised_curvature import LinearisedCurvature
from comanip.optim.active_set_newton import newton_solve
from comanip.optim.newton_loop import never
from comanip.planning.path_limits import LIMIT_TOLERANCE, PathLimits
from comanip.planning.plan import Plan, PlanStatus, with_reach_check
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.start_threads import StartThreads, usable_cores
from comanip.planning.starts import StartPolicy
from comanip.planning.terms import Curvature

SOLVER_METHODS = ("newton", "ipopt")
COLD_SEARCHES = ("ranked", "all")
LOCAL_OPTIMUM_TOLERANCE = 1e-6
"""Relative objective difference below which two converged plans of one cold search count as the same local
optimum (a point-mass reach library keeps one plan per local optimum)."""
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
    without a library, or away from its ready pose, runs every guess as 'all' does. benchmarks/cold_quality.py
    compares 'ranked' with 'all' under the cold-search rule (docs/results/speed.md)."""
    narrow_ratio: float = 20.0
    """Reach distance over goal width beyond which local optima compete in a point mass's 'ranked' cold solve: it
    starts from the reach library's plans near each of them (:meth:`ReachLibrary.local_optima
    <comanip.planning.starts.reach_library.ReachLibrary.local_optima>`) instead of the nearest solved reach, or,
    from a start whose motion carries the hand on, solves from every minimum-jerk guess. The distance counts from
    the start and from where a stop of its motion ends. Far, narrow goals of the planar preset have several local
    optima (the lowest-objective minimum-jerk start ended 0.7 % worse on 1 of 200 random problems, at 54 widths;
    none below 20 widths on any point-mass preset)."""
    far_warm_start: float = 3.0
    """Goal widths: a warm start (a plan to another goal) whose final hand position is farther than this
    from the new goal lies where the goal's reward underflows, so ``n_starts`` fresh reaches compete with it. For
    a plan that carries its goal sensitivity the position is where the predicted start ends."""
    arm_library: str | None = None
    """An arm's reach library for 'ranked' cold solves from its ready pose, at rest or moving (its nearest plan
    also competes with a warm start there): a file written by ``comanip library`` (.npz) for this model. None:
    the library shipped for the model (``franka_rest``), if any (:mod:`comanip.planning.starts.arm_reach_library`)."""
    abandon_after: int = 100
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
    virtual machine is ten times slower (a first build takes about a minute for the Panda); for a point mass,
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
        self._curvature = self._newton_terms() if self.options.method == "newton" else None
        body, H = self.model.body, self.model.H
        self._torque_bounds = (np.tile(-body.tau_max, H), np.tile(body.tau_max, H))
        self._limits = PathLimits.of(self.model)
        self._blas = _SingleThreadBlas()
        self._ipopt = self._ipopt_solver() if self.options.method == "ipopt" else None
        self.starts = StartPolicy(self.model, self.options, problem, self._curvature, self._limits, self._solve_reach)
        """Where each solve starts (:class:`~comanip.planning.starts.StartPolicy`)."""
        self._solving_time = 0.0 if self.options.compile is None and body.is_linear and self._curvature else None
        threads = min(self.options.n_starts, usable_cores()) if self.options.threads is None else self.options.threads
        self._start_threads = StartThreads(self._curvature, threads) \
            if threads > 1 and isinstance(self._curvature, LinearisedCurvature) else None

    def _solve_reach(self, start, goal, width) -> list[np.ndarray]:
        """The distinct converged plans (torques (H, n), lowest objective first) of a cold solve from the
        minimum-jerk guesses: a point-mass reach library's entry. Plans whose objectives agree to
        ``LOCAL_OPTIMUM_TOLERANCE`` (relative) count as one."""
        params = ReachParameters(start, goal, width)
        with self._blas:
            results = sorted(self._results_from(self.starts.searched_guesses(params), params, np.inf), key=_rank)
        kept: list[SolverResult] = []
        for result in results:
            within_limits = not result.violation > LIMIT_TOLERANCE  # IPOPT reports no violation (NaN)
            if result.status in CONVERGED and within_limits and \
                    all(abs(result.fun - other.fun) > LOCAL_OPTIMUM_TOLERANCE * abs(other.fun) for other in kept):
                kept.append(result)
        return [result.x for result in kept] or [results[0].x]

    @property
    def curvature(self) -> Curvature | None:
        """The Newton method's objective, gradient and Hessian terms (None for ``method="ipopt"``); the goal
        estimator reuses them."""
        return self._curvature

    @property
    def _max_iterations(self) -> int:
        if self.options.max_iterations is not None:
            return self.options.max_iterations
        return self.options.point_mass_iterations if self.model.body.is_linear else self.options.arm_iterations

    @property
    def _tolerance(self) -> float:
        """The Newton method's convergence tolerance: ``arm_tolerance`` for nonlinear bodies, if set."""
        options = self.options
        return options.tolerance if self.model.body.is_linear or options.arm_tolerance is None else options.arm_tolerance

    def _newton_terms(self):
        """Objective, gradient and Hessian for the Newton method: exact for linear bodies, structured
        approximation with secant corrections for nonlinear ones."""
        compile = self.options.compile
        if self.model.body.is_linear:
            return ReachCurvature(self.problem, compile=compile)
        return LinearisedCurvature(self.problem, compile=compile is not False)

    def _ipopt_solver(self) -> IpoptSolver:
        """IPOPT on the whole single-shooting problem with CasADi's exact Hessian."""
        problem = self.problem
        params = ca.vertcat(problem.s0, problem.goal, problem.width)
        ipopt = {"print_level": 0, "sb": "yes", "max_iter": self._max_iterations,
                 "tol": self.options.tolerance, **self.options.ipopt}
        deadline = IpoptDeadline(problem.tau.numel(), params.shape[0])
        solver = ca.nlpsol("planner", "ipopt",
                           {"x": ca.vec(problem.tau), "p": params, "f": -problem.objective / problem.best_objective},
                           {"ipopt": ipopt, "print_time": False, "error_on_fail": False, "iteration_callback": deadline})
        return IpoptSolver(solver, deadline)

    def check_inputs(self, start, goal, width) -> tuple[np.ndarray, np.ndarray, float]:
        """Validated (start (nx,), goal (d,), width) or ValueError naming the argument (:func:`reach_inputs`)."""
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
        with self._blas:  # the starts' small products too: one BLAS switch per solve
            guesses = self.starts.guesses(params, warm_start, budgeted=max_wall_time is not None,
                                          goal_q=goal_q if warm_start is None else None)
            from_library = warm_start is None and self.starts.from_arm_library(start)
            plan = with_reach_check(self._solve_from(guesses, params, t_begin, max_wall_time, until_converged=from_library))
        self._count_solving_time(plan.solve_time)
        return with_plausibility_warnings(self.model, plan)  # a point mass is a person's hand: name implausible reaches

    def _count_solving_time(self, seconds: float) -> None:
        """Add a solve's time; past ``compile_after`` seconds, start the point mass's background compile."""
        if self._solving_time is None:
            return
        self._solving_time += seconds
        if self._solving_time >= self.options.compile_after:
            self._curvature.compile_in_background()
            self._solving_time = None

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
        return self._make_plan(torque, params, status=PlanStatus.UNREACHABLE, success=False, message=message,
                               solve_time=time.perf_counter() - t_begin, iterations=0)

    def _sensitivity_of(self, result: SolverResult) -> GoalSensitivity | None:
        """The goal sensitivity of a converged point-mass solve (from the Newton method's last factorisation and
        the evaluation at the plan); None otherwise."""
        curvature = self._curvature
        if curvature is None or not curvature.exact or not result.success or result.local_model is None \
                or result.local_model.factor is None:
            return None
        return GoalSensitivity(curvature, result.local_model.factor, result.local_model.data, self._blas)

    def _solve_from(self, guesses, params: ReachParameters, t_begin: float, max_wall_time: float | None,
                    until_converged: bool = False) -> Plan:
        """The best plan from the guesses (each (H, n)): solved in turn, or, when every guess is solved, as the
        cold search :meth:`_searched` runs them. ``until_converged``: stop at the first whose solve converges
        ('solved') within the limits and ends at the goal (later guesses are fallbacks). A solve that stalled
        ('solved_acceptable', along a redundant arm's flat directions) does not stop the search: on 200 cold
        franka_rest problems 5 library starts did, one of them 6.4e-6 above the plan of the full search
        (benchmarks/cold_quality.py, problem 175)."""
        deadline = np.inf if max_wall_time is None else t_begin + max_wall_time
        # The Newton systems have a few hundred unknowns: one BLAS thread solves them fastest, and a
        # multi-threaded BLAS on a busy machine waits for cores.
        with self._blas:
            results = self._results_from(guesses, params, deadline, until_converged)
        # The plan within the limits with the lowest objective wins, whatever its status: a start that stalls short
        # of the tolerances can still be far better than one that converged on the zero-reward plateau (seen on the
        # Panda), and the status then says it did not converge.
        best = min(results, key=_rank)
        evaluation = None if best.local_model is None else Evaluation(best.fun, None, best.local_model.data)
        plan = self._make_plan(best.x, params, evaluation, status=best.status, success=best.success, message=best.message,
                               solve_time=time.perf_counter() - t_begin, iterations=sum(result.nit for result in results))
        plan.goal_sensitivity = self._sensitivity_of(best)
        return plan

    def _results_from(self, guesses, params: ReachParameters, deadline: float, until_converged: bool = False) -> list[SolverResult]:
        """One result per guess solved (each (H, n)): in turn, or, when every guess is solved, as the cold search
        :meth:`_searched` runs them (``until_converged``: :meth:`_solve_from`)."""
        if until_converged or len(guesses) == 1 or self._curvature is None:
            return self._solved_in_turn(guesses, params, deadline, until_converged)
        return [self._finite(result, guess, params) for guess, result in zip(guesses, self._searched(guesses, params, deadline))]

    def _solved_in_turn(self, guesses, params: ReachParameters, deadline: float, until_converged: bool) -> list[SolverResult]:
        """The guesses' solves one after another, each to convergence, until the deadline has passed (after the
        first) or, ``until_converged``, the best so far is 'solved' and ends at the goal."""
        results = []
        for guess in guesses:
            if results and time.perf_counter() > deadline:
                break
            results.append(self._finite(self._run_solver(guess, params, deadline), guess, params))
            best = min(results, key=_rank)
            if until_converged and best.status == Status.SOLVED and self._ends_at_goal(best.x, params):
                break
        return results

    def _searched(self, guesses, params: ReachParameters, deadline: float) -> list[SolverResult]:
        """Every guess's solve, side by side on the start threads if the planner has them (:attr:`SolverOptions.threads`).
        'ranked' abandons a start that has not converged after ``abandon_after`` iterations when a start that has
        converged within the limits by then has a lower objective than it has there; 'all' runs every start to the
        end. The results do not depend on the threads: each start is solved alone, in the same two stages."""
        threads = self._start_threads
        terms = threads.terms(len(guesses)) if threads is not None else [self._curvature] * len(guesses)
        run = threads.map if threads is not None else _one_after_another
        budget = self._max_iterations
        checkpoint = min(budget, self.options.abandon_after) if self.options.cold_search == "ranked" else budget
        solves = [self._newton_solve(guess, params, deadline, curvature) for guess, curvature in zip(guesses, terms)]
        results = run(lambda solve: solve.advance(checkpoint), solves)
        lowest = min((result.fun for result in results if result.status in CONVERGED and result.violation <= LIMIT_TOLERANCE),
                     default=np.inf)
        going_on = [k for k, (solve, result) in enumerate(zip(solves, results)) if not solve.finished and not result.fun > lowest]
        for k, result in zip(going_on, run(lambda k: solves[k].advance(budget), going_on)):
            results[k] = result
        return [self._as_torques(result) for result in results]

    def _finite(self, result: SolverResult, guess: np.ndarray, params: ReachParameters) -> SolverResult:
        """The result, or, where the solver returned a non-finite plan, the guess (H, n) with status 'failed'."""
        if np.isfinite(result.x).all() and np.isfinite(result.fun):
            return result
        objective = self.problem.objective_value(guess, params.start, params.goal, params.width) / self.problem.normaliser(params.width)
        return SolverResult(guess, objective, Status.FAILED, "solver returned a non-finite plan; returning the initial guess",
                            result.nit, np.inf)

    def _ends_at_goal(self, torque: np.ndarray, params: ReachParameters) -> bool:
        """True when the mean end effector of torques (H, n) ends within the goal width of the goal (a converged
        plan can rest on the zero-reward plateau instead)."""
        model, curvature = self.model, self._curvature
        q_end = curvature.mean_path(curvature.value_and_data(np.ravel(torque), params).data)[-1, : model.n]
        end = np.asarray(model.body.kinematics_function(q_end)[0]).ravel()
        return bool(np.linalg.norm(end - params.goal) <= params.width)

    def _make_plan(self, torque, params: ReachParameters, evaluation: Evaluation | None = None, **fields) -> Plan:
        """The Plan of torques (H, n); ``evaluation``: the Newton method's own evaluation at them (its f and data),
        from which an arm's belief is taken without evaluating again."""
        curvature = self._curvature
        if curvature is None or not curvature.carries_belief:  # a point mass's expanded rollout is cheap
            return self.problem.make_plan(torque, params, **fields)
        evaluation = evaluation if evaluation is not None else curvature.evaluate(np.ravel(torque), params)
        return self.problem.make_plan(torque, params, belief=curvature.trajectory(evaluation.data),
                                      objective=evaluation.f * curvature.normaliser(params.width), **fields)

    def _run_solver(self, guess: np.ndarray, params: ReachParameters, deadline: float) -> SolverResult[np.ndarray, LocalModel]:
        """One solve from torques guess (H, n) until ``deadline`` (perf_counter, s): x the torques (H, n),
        fun the normalised objective."""
        if self._curvature is None:
            return self._run_ipopt(guess, params, deadline)
        return self._as_torques(self._newton_solve(guess, params, deadline, self._curvature).advance(self._max_iterations))

    def _newton_solve(self, guess: np.ndarray, params: ReachParameters, deadline: float, curvature: Curvature) -> NewtonSolve:
        """The Newton method's solve from torques guess (H, n) until ``deadline`` (perf_counter, s), evaluated with
        ``curvature`` (the planner's terms or a start's own copy of them), to run in stages."""
        value = (lambda x: curvature.value_and_data(x, params)) if curvature.cheap_value else None
        return newton_solve(lambda x: curvature.evaluate(x, params), curvature.hessian, np.ravel(guess),
                            *self._torque_bounds, tolerance=self._tolerance, secant=not curvature.exact,
                            hessian_refresh=1 if curvature.exact else self.options.hessian_refresh,
                            constraints=self._limits.for_newton(curvature) if self._limits.active else None,
                            constraint_tolerance=LIMIT_TOLERANCE, value=value,
                            expired=(lambda: time.perf_counter() > deadline) if deadline < np.inf else never)

    def _as_torques(self, result: SolverResult[np.ndarray, LocalModel]) -> SolverResult[np.ndarray, LocalModel]:
        """The result with x as torques (H, n)."""
        result.x = result.x.reshape(self.model.H, self.model.n)
        return result

    def _run_ipopt(self, guess: np.ndarray, params: ReachParameters, deadline: float) -> SolverResult[np.ndarray, LocalModel]:
        solver = self._ipopt.function
        self._ipopt.deadline.time = deadline
        result = solver(x0=np.ravel(guess), p=params.vector)
        stats = solver.stats()
        status = ipopt_status(stats, self._ipopt.deadline)
        torque = np.asarray(result["x"]).reshape(self.model.H, self.model.n)
        return SolverResult(torque, float(result["f"]), status, stats["return_status"], int(stats.get("iter_count", 0)), np.nan)


class _SingleThreadBlas:
    """A context in which the BLAS libraries loaded when it was made run on one thread (their thread counts are
    restored on leaving; nested contexts leave them to the outermost). threadpoolctl's own ``limit`` looks the
    libraries up on every entry, which costs about as much as a point mass's Newton step."""

    def __init__(self):
        self._libraries = ThreadpoolController().select(user_api="blas").lib_controllers
        self._depth, self._restore = 0, []

    def __enter__(self):
        if self._depth == 0:
            self._restore = [(library, library.num_threads) for library in self._libraries if library.num_threads != 1]
            for library, _ in self._restore:
                library.set_num_threads(1)
        self._depth += 1
        return self

    def __exit__(self, *exception):
        self._depth -= 1
        if self._depth == 0:
            for library, threads in self._restore:
                library.set_num_threads(threads)
        return False


def _distance(body, q: np.ndarray, point: np.ndarray) -> float:
    """Distance (m) of the body's end effector at joint position q (n,) from a point (d,)."""
    return float(np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - point))


def _one_after_another(function, items) -> list:
    """[function(item) for each item]: the start threads' ``map``, in the calling thread."""
    return [function(item) for item in items]


def _rank(candidate: SolverResult) -> tuple[bool, float]:
    """Order of the starts' results: within the limits first, then the lower normalised objective."""
    return candidate.status == Status.CONSTRAINTS_VIOLATED, candidate.fun


def reach_inputs(model: ReachingModel, start, goal, width) -> tuple[np.ndarray, np.ndarray, float]:
    """Validated (start (nx,), goal (d,), width (m)) of a reach for ``model``, or ValueError naming the argument;
    no planner needed, so callers can check every input before building one.

    A start of [q; qdot] (2n,) for a model with activation stages gets them at zero force."""
    size = 2 * model.n if np.shape(start) == (2 * model.n,) else model.state_size
    start = model.full_state(as_bounded_vector("start", start, size, "state [q; qdot] in m and m/s, or rad and rad/s"
                                       + (f", optionally followed by the {model.state_size - 2 * model.n} activation states"
                                          if size != 2 * model.n else "")))
    goal = as_position("goal", goal, model.d)
    width = model.width if width is None else as_goal_width("width", width)
    return start, goal, width


def plan_reach(model: ReachingModel, start, goal, width: float | None = None, **solve_options) -> Plan:
    """One-off plan: builds a :class:`Planner` for the model and solves once. Reuse a Planner in loops."""
    return Planner(model).solve(start, goal, width, **solve_options)
