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
  Several times faster than IPOPT on the point masses, to the same optimum (benchmarks/README.md).
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

from comanip.arguments import (as_bounded_vector, as_count, as_goal_width, as_matrix, as_optional_positive, as_position,
                               as_positive)
from comanip.model import ReachingModel
from comanip.plausibility import with_plausibility_warnings
from comanip.planning.arm_reach_library import CANDIDATE_ENTRIES, WARM_CANDIDATE_ENTRIES, ArmReachLibrary, bundled_library
from comanip.planning.curvature import ReachCurvature
from comanip.planning.initial_guess import (brake_durations, braked_torques, guess_durations, linear_dynamics_of,
                                          minimum_jerk_torques, retargeted_torques)
from comanip.optim import SolverResult, Status, cholesky_solve
from comanip.planning.ipopt_status import IpoptDeadline, ipopt_status
from comanip.caching.buffered_function import BufferedFunction
from comanip.planning.linearised_curvature import LinearisedCurvature
from comanip.optim.active_set_newton import newton_minimize
from comanip.planning.path_limits import LIMIT_TOLERANCE, PathLimits
from comanip.planning.plan import Plan, with_reach_check
from comanip.planning.reach_library import ReachLibrary, is_symmetric
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.terms import Curvature

SOLVER_METHODS = ("newton", "ipopt")
COLD_SEARCHES = ("ranked", "all")
WITNESS_STEPS = 3
"""Damped least-squares steps from a warm-start plan's final position that may show a goal reachable without the
full inverse kinematics (:meth:`Planner._goal_joints`): on 30 chained warm ``franka_rest`` goals 22–120 mm from
the previous plan's final hand position, one step left up to 18 mm, two 0.3 mm, three 1e-4 mm
(benchmarks/franka_witness_steps.py)."""


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
    linearly, and the iterations from 1e-6 to 1e-8 only polish the gradient: on 16 cold and 16 warm
    ``franka_rest`` problems, stopping at 1e-6 changed J by at most 1.1e-9 relative and the mean hand paths by at
    most 0.004 mm, and took a sixth fewer iterations (benchmarks/franka_solver_options.py). 1e-5 saves about as
    many again on ``franka_rest`` (J within 1e-7), but the paper's ``franka`` plans lie on a flat valley where it
    stopped one warm plan 2e-3 above the previous solver's J (benchmarks/README.md, "Franka warm solves")."""
    hessian_refresh: int = 3
    """Nonlinear bodies: the approximate Hessian is assembled every this many Newton iterations, and after any step
    the line search shortened or taken with a limit in the working set; in between it is kept with its secant
    corrections updated (:func:`comanip.optim.active_set_newton.newton_minimize`). 1: every iteration. Point masses (exact
    Hessian) assemble theirs as before whatever this says. On the ``franka_rest`` problems above (tolerance 1e-8),
    3 took as many iterations as 1 (447 against 454), 62 % of the assemblies and ended at the same plans (J within
    1.6e-9); at tolerance 1e-6, 2 and 4 were slower than 3 (benchmarks/franka_solver_options.py)."""
    n_starts: int = 3
    """Minimum-jerk initial guesses of a cold solve (durations spread over the horizon). A warm-started
    solve uses the warm start only."""
    cold_search: str = "ranked"
    """How a cold solve starts. 'all': from each of the ``n_starts`` minimum-jerk guesses, keeping the best
    converged plan. 'ranked': from the lowest-objective start among those guesses and, for a point mass, a solved
    reach turned to the goal, for an arm at its ready pose, the nearest plans of its reach library
    (:meth:`Planner._cold_start`), about as fast as a warm solve, with second solves where local optima compete
    (point masses) or the guesses as fallbacks (arms). An arm without a library, or away from its ready pose,
    runs every guess as 'all' does. Against 'all' on 200 random cold problems per point-mass preset: 0 worse,
    11 better, 789 equal (1e-6 relative; benchmarks/cold_quality.py)."""
    narrow_ratio: float = 20.0
    """Reach distance over goal width beyond which a 'ranked' cold solve also solves from the best minimum-jerk
    guess (without a reach library: from every guess): far, narrow goals of the planar preset have several
    local optima (the lowest-objective guess alone ended 0.7 % worse on 1 of 200 random problems, at 54 widths;
    none below 20 widths on any point-mass preset)."""
    far_warm_start: float = 3.0
    """Goal widths: a warm start (a plan to another goal) whose final hand position is farther than this
    from the new goal lies where the goal's reward underflows, so ``n_starts`` fresh reaches compete with it."""
    arm_library: str | None = None
    """An arm's reach library for 'ranked' cold solves from its ready pose, at rest or moving (its nearest plan
    also competes with a warm start there): a file written by ``comanip library`` (.npz) for this model. None:
    the library shipped for the model (``franka_rest``), if any (:mod:`comanip.planning.arm_reach_library`)."""
    ipopt: dict = field(default_factory=dict)
    """Extra IPOPT options, passed through (e.g. {"hessian_approximation": "limited-memory"})."""
    compile: bool | None = None
    """Compile the Newton method's per-solve function to C (cached on disk, see comanip.caching.compiled).
    True: when the planner is built. False: never. None: when built for nonlinear bodies, where CasADi's
    virtual machine is ten times slower (a first build takes about a minute for the Panda); for a point mass,
    in a background thread once the planner has spent ``compile_after`` seconds solving, its solves going on
    uncompiled meanwhile: compiling costs 3–17 s for every new model, which short-lived planners (a fit's,
    one per parameter set) would not win back, while a long-lived one (a control loop, a sweep) solves
    about a third faster afterwards (benchmarks/README.md). A model compiled before (by any planner, in any
    process, with this version of the package) is loaded compiled from the disk cache when built."""
    compile_after: float = 2.0
    """Seconds of solving (the sum of ``plan.solve_time``) after which a point-mass planner with ``compile=None``
    compiles its per-solve function in the background."""

    def __post_init__(self):
        if self.method not in SOLVER_METHODS:
            raise ValueError(f"method must be one of {SOLVER_METHODS}, got {self.method!r}")
        as_count("max_iterations", self.max_iterations, optional=True)
        for name in ("n_starts", "point_mass_iterations", "arm_iterations", "hessian_refresh"):
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
        self._torque_box = tuple(bound.reshape(H, body.n) for bound in self._torque_bounds)  # the same, (H, n)
        self._unbounded = not np.isfinite(body.tau_max).any()
        self._limits = PathLimits.of(self.model)
        self._linear_dynamics = linear_dynamics_of(body) if body.is_linear else None
        # a linear body's joint move (n,) per task-space move (d,): the pseudo-inverse of its constant Jacobian
        self._task_to_joint_shift = np.linalg.pinv(np.asarray(body.kinematics_function(np.zeros(body.n))[1])) \
            if body.is_linear else None
        self._blas = _SingleThreadBlas()
        self._ipopt, self._deadline = self._ipopt_solver() if self.options.method == "ipopt" else (None, None)
        self._library = self._reach_library()
        ranked_arm = self.options.cold_search == "ranked" and not body.is_linear
        self._arm_library = self._arm_reach_library() if ranked_arm else None
        self._solving_time = 0.0 if self.options.compile is None and body.is_linear and self._curvature else None
        self._last_solution: _LastSolution | None = None  # the last point-mass plan's, for _predicted
        self._kinematics = BufferedFunction(body.kinematics_function)

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
        """Solved reaches to start 'ranked' cold solves from (:mod:`comanip.planning.reach_library`), for a
        point mass whose objective is unchanged by turning and shifting the problem; None otherwise."""
        model = self.model
        if self.options.cold_search != "ranked" or not model.body.is_linear or model.d != model.n or model.state_size % model.n:
            return None
        if not is_symmetric(self.problem):
            return None

        def solve(start, goal, width):
            guesses = self._searched_guesses(start, goal, width)
            return self._solve_from(guesses, start, goal, width, time.perf_counter(), None).torque

        return ReachLibrary(solve, model.n, model.state_size, model.width)

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

    def _ipopt_solver(self) -> tuple[ca.Function, IpoptDeadline]:
        """IPOPT on the whole single-shooting problem with CasADi's exact Hessian, and the deadline its
        iteration callback watches (set before each solve)."""
        problem = self.problem
        params = ca.vertcat(problem.s0, problem.goal, problem.width)
        ipopt = {"print_level": 0, "sb": "yes", "max_iter": self._max_iterations,
                 "tol": self.options.tolerance, **self.options.ipopt}
        deadline = IpoptDeadline(problem.tau.numel(), params.shape[0])
        solver = ca.nlpsol("planner", "ipopt",
                           {"x": ca.vec(problem.tau), "p": params, "f": -problem.objective / problem.best_objective},
                           {"ipopt": ipopt, "print_time": False, "error_on_fail": False, "iteration_callback": deadline})
        return solver, deadline

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
                for a point mass's plan this planner solved last, from the same start at the same width, by
                the optimum's first-order sensitivity to the goal (:meth:`_predicted`); otherwise by joint-space
                minimum-jerk corrections. From an arm reach library's ready pose the library's nearest plan, moved
                onto the goal (and braked, from a moving start), competes too.
            max_wall_time: wall-time budget (s) for the whole solve; the best plan so far is returned with
                status 'max_wall_time' when it runs out. A budgeted cold solve starts only from reach-library
                entries solved before (:meth:`_cold_start`): a new one would be a whole solve outside the budget.

        Returns:
            A :class:`Plan`; never raises on a failed solve (check ``plan.success``: converged and reaching). For a
            point mass, a reach no person makes (too far, too fast) keeps its status and gets a warning in its
            message and ``extras['warnings']`` (:mod:`comanip.plausibility`).
        """
        start, goal, width = self.check_inputs(start, goal, width)
        max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")
        t_begin = time.perf_counter()
        goal_q = None if self.model.body.is_linear else self._goal_joints(start, goal, width, warm_start)
        unreachable = self._unreachable_plan(start, goal, width, goal_q, t_begin)
        if unreachable is not None:
            return unreachable
        with self._blas:  # the starts' small products too: one BLAS switch per solve
            guesses = self._initial_guesses(start, goal, width, warm_start, budgeted=max_wall_time is not None,
                                            goal_q=goal_q if warm_start is None else None)
            from_library = warm_start is None and self._arm_library is not None and self._arm_library.serves(start)
            plan = with_reach_check(self._solve_from(guesses, start, goal, width, t_begin, max_wall_time,
                                                     until_converged=from_library))
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

        A cold solve: the inverse kinematics from the start (about 15 ms for the Panda; its guesses reach for
        it). A warm start from a plan: ``WITNESS_STEPS`` damped least-squares steps (clipped to the limits) from
        the plan's final mean position, about 0.1 ms, when they bring the hand within w of the goal (a warm
        solve to a goal moved by a few cm: they do), else the inverse kinematics from that position."""
        model, body = self.model, self.model.body
        if not (isinstance(warm_start, Plan) and warm_start.mean.shape == (model.H + 1, model.state_size)):
            return body.inverse_kinematics(goal, start[: model.n])
        final = warm_start.mean[-1, : model.n]
        near = body.clip_to_limits(body.least_squares_inverse_kinematics(goal, final, WITNESS_STEPS))
        return near if _distance(body, near, goal) <= width else body.inverse_kinematics(goal, final)

    def _unreachable_plan(self, start, goal, width, goal_q: np.ndarray | None, t_begin: float) -> Plan | None:
        """A plan with status 'unreachable' when no joint position within the limits puts the end effector
        within the goal width of the goal (the residual of ``goal_q`` (n,), :meth:`_goal_joints`, > w); None
        otherwise, and for point masses (``goal_q`` None: they reach everywhere). An arm is checked before any
        solver work."""
        model, body = self.model, self.model.body
        if goal_q is None:
            return None
        residual = _distance(body, goal_q, goal)
        if residual <= width:
            return None
        message = (f"goal {np.round(goal, 4).tolist()} m is {residual:.3f} m from the nearest point the {body.name} reaches "
                   f"within its joint limits, beyond the goal width {width} m; no plan was solved (the arm holds still)")
        torque = np.zeros((model.H, model.n))
        params = np.concatenate([start, goal, [width]])
        return self._make_plan(torque, params, status=Status.UNREACHABLE, success=False, message=message,
                               solve_time=time.perf_counter() - t_begin, iterations=0)

    def _initial_guesses(self, start, goal, width, warm_start, budgeted: bool = False,
                         goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The starts of a solve; ``goal_q`` (n,): the goal's inverse kinematics from the start, if known."""
        model = self.model
        if warm_start is None:
            return self._cold_start(start, goal, width, budgeted, goal_q)
        torque = warm_start.torque if isinstance(warm_start, Plan) else warm_start
        torque = as_matrix("warm_start", torque, (model.H, model.n), "torques, N·m or N")
        if not (isinstance(warm_start, Plan) and warm_start.goal.shape == goal.shape
                and warm_start.mean.shape[0] == model.H + 1 and not np.array_equal(warm_start.goal, goal)):
            return [torque]
        # a plan for another goal: also try it moved onto the new goal (by the tangential predictor if this
        # planner solved it last: it gave the best start in 398 of 400 warm point-mass solves, against the
        # minimum-jerk retargeting's 1), and start from the best
        predicted = self._predicted(warm_start, start, goal, width)
        candidates = [torque, predicted] if predicted is not None else \
            self._retargeted(torque, warm_start.mean, warm_start.goal, goal)
        if self._arm_library is not None and self._arm_library.serves(start):
            # the solved reach nearest to the goal competes too: on 50 chained warm franka_rest solves to goals
            # moved by up to 5 cm per axis it was the best start 48 times (15 → 10 Newton iterations, J within 3e-9)
            candidates += self._library_candidates(start, goal, WARM_CANDIDATE_ENTRIES)
        if np.linalg.norm(warm_start.ee_mean[-1] - goal) > self.options.far_warm_start * width:
            # far beyond the goal's reward (it underflows there): fresh reaches compete too
            candidates += self._cold_guesses(start, goal, self.options.n_starts)
        return [self._lowest_objective(candidates, start, goal, width)]

    def _predicted(self, warm_start: Plan, start, goal, width) -> np.ndarray | None:
        """The first-order prediction of the optimal torques (H, n) for ``goal`` from a point-mass plan this
        planner solved last (same start and width, another goal): tau* + (d tau*/d goal) (goal - its goal), the
        tangential predictor of parametric optimisation; None for any other warm start. On warm planar solves
        to goals moved by up to 5 cm its gradient is about a tenth of the retargeted plan's, and the solves
        take 4.7 instead of 5.9 Newton iterations (benchmarks/README.md)."""
        remembered = self._goal_sensitivity
        if remembered is None or remembered[0] is not warm_start.torque or warm_start.width != width \
                or not np.array_equal(warm_start.start, start):
            return None
        model = self.model
        return warm_start.torque + (remembered[1] @ (goal - warm_start.goal)).reshape(model.H, model.n)

    @property
    def _goal_sensitivity(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(torques (H, n) of the planner's last plan, their d tau*/d goal (H·n, d)) if that was a converged
        point-mass solve (:class:`_LastSolution`), else None; the sensitivity is computed on the first request."""
        last = self._last_solution
        if last is None:
            return None
        if last.sensitivity is None:
            with self._blas:
                last.sensitivity = -cholesky_solve(last.factor, self._curvature.goal_cross_derivative(last.data))
        return last.torque, last.sensitivity

    def _solution_of(self, result: SolverResult, torque: np.ndarray) -> _LastSolution | None:
        """What :meth:`_goal_sensitivity` needs of a converged point-mass solve (the Newton method's last
        factorisation and the evaluation at the plan), kept for the planner's last plan; None otherwise."""
        curvature = self._curvature
        if curvature is None or not curvature.exact or not result.success or result.local_model is None \
                or result.local_model[0] is None:
            return None
        factor, data = result.local_model
        return _LastSolution(torque, factor, data)

    def _retargeted(self, torque: np.ndarray, mean: np.ndarray, planned_goal: np.ndarray, goal: np.ndarray) -> list[np.ndarray]:
        """A plan's torques (H, n) for ``planned_goal`` (d,) and the same moved onto ``goal`` (d,) by joint-space
        minimum-jerk corrections of four durations (:func:`retargeted_torques`, along its mean (H+1, nx))."""
        model, body = self.model, self.model.body
        if self._linear_dynamics is not None:  # x_ee linear in q: one constant pseudo-inverse
            shift_q = self._task_to_joint_shift @ (goal - planned_goal)
        else:
            J = np.asarray(body.kinematics_function(mean[-1, : model.n])[1])
            shift_q = np.linalg.lstsq(J, goal - planned_goal, rcond=None)[0]
        return [torque] + retargeted_torques(body, model.h, model.H, torque, shift_q, guess_durations(model.duration, 4),
                                             mean, self._linear_dynamics)

    def _lowest_objective(self, candidates: list[np.ndarray], start, goal, width) -> np.ndarray:
        """The candidate torques (H, n), clipped to the torque bounds, of lowest objective among those whose mean
        path keeps the joint limits (all candidates if none does)."""
        params = np.concatenate([start, goal, [width]])
        low, high = self._torque_box
        if self._unbounded:  # no torque bound (the point masses): clipping would only copy
            return min(candidates, key=lambda c: self._start_rank(c, params))
        return min((np.clip(c, low, high) for c in candidates), key=lambda c: self._start_rank(c, params))

    def _start_rank(self, torque: np.ndarray, params: np.ndarray) -> tuple[bool, float]:
        """(mean path beyond a joint limit, objective) of a start (H, n): its order among candidates. A start
        beyond the limits can have the lowest objective and still be the worst: the solver must first bring it
        back (on the Panda, starts retargeted far ended 'constraints_violated')."""
        curvature = self._curvature
        if curvature is None or not curvature.carries_belief or not self._limits.active:
            return False, self._objective(torque, params)
        f, data = curvature.value_and_data(np.ravel(torque), params)
        return self._limits.violation(curvature.mean_path(data)) > LIMIT_TOLERANCE, f

    def _cold_start(self, start, goal, width, budgeted: bool = False, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The guesses a cold solve runs (``SolverOptions.cold_search``).

        An arm at the ready pose of its reach library: :meth:`_arm_library_starts`. 'all', or another nonlinear
        body or start: every minimum-jerk guess. 'ranked', for a symmetric point mass: the
        candidate of lowest objective (evaluating one costs about a hundredth of solving from it) among the
        minimum-jerk guesses and the nearest solved reach of the planner's :class:`ReachLibrary` (from a moving
        start with minimum-jerk moves that bring the start's motion to rest superposed: the mean is affine in
        the torques and the start). Where several local optima compete the lowest-objective start can end on
        a worse one, so the plan is compared with others: a goal farther than ``narrow_ratio`` widths also runs
        the best minimum-jerk guess, and a start whose motion alone would carry the hand farther than the goal
        within the horizon runs every minimum-jerk guess instead, as 'all' does (the plan can brake or ride the
        motion: the Cartesian preset's moving starts ended up to 0.1 % worse in 4 of 100 otherwise,
        benchmarks/cold_quality.py). A ``budgeted`` solve (max_wall_time given) uses only library reaches solved
        before: solving a new one is a whole cold search outside the budget (about 0.1 s on the Cartesian preset).
        """
        if self._arm_library is not None and self._arm_library.serves(start):
            return self._arm_library_starts(start, goal, width, goal_q)
        if self._library is None:
            return self._searched_guesses(start, goal, width, goal_q)
        model = self.model
        motion = start.copy()
        motion[: model.n] = 0.0
        moving = bool(np.any(motion))
        guesses = self._cold_guesses(start, goal, self.options.n_starts)
        if moving and self._drift(start, goal, width) > np.linalg.norm(goal - start[: model.n]):
            return guesses
        params = np.concatenate([start, goal, [width]])
        objectives = [self._objective(guess, params) for guess in guesses]
        first_best = min(range(len(guesses)), key=objectives.__getitem__)
        best_guess = guesses[first_best]
        turned = self._library.guess(start, goal, width, solve_missing=not budgeted)
        if turned is None:  # the goal at the start, or a budgeted solve without the entry: as without a library
            return guesses if self._narrow(start, goal, width) else [best_guess]
        candidates = [turned]
        if moving:
            candidates = list(turned + minimum_jerk_torques(model.body, model.h, model.H, motion, np.zeros(model.n),
                                                            guess_durations(model.duration, self.options.n_starts),
                                                            self._linear_dynamics))
        scored = [(self._objective(candidate, params), candidate) for candidate in candidates] + \
            [(objectives[first_best], best_guess)]  # the guess's objective as evaluated above
        best = min(scored, key=lambda pair: pair[0])[1]
        return [best, best_guess] if self._narrow(start, goal, width) and best is not best_guess else [best]

    def _arm_library_starts(self, start, goal, width, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """An arm's cold starts from its ready pose (:mod:`comanip.planning.arm_reach_library`): first the
        lowest-objective torques (H, n) among the minimum-jerk guesses and the plans of the nearest library
        entries, each as solved and moved onto the goal; then the minimum-jerk guesses, which
        :meth:`_solve_from` runs only if no start before them converged."""
        guesses = self._cold_guesses(start, goal, self.options.n_starts, goal_q)
        candidates = guesses + self._library_candidates(start, goal, CANDIDATE_ENTRIES)
        return [self._lowest_objective(candidates, start, goal, width)] + guesses

    def _library_candidates(self, start, goal, entries: int) -> list[np.ndarray]:
        """The plans (H, n) of the arm reach library's ``entries`` entries nearest to ``goal`` (d,), each as solved
        and moved onto the goal (:meth:`_retargeted`); ``start`` (2n,) has the library's joint positions, and if it
        moves, each candidate gets the braking moves of :func:`braked_torques` instead."""
        library, model, candidates = self._arm_library, self.model, []
        velocity = start[model.n:2 * model.n]
        for entry_goal, torque in library.nearest(goal, entries):
            entry_params = np.concatenate([library.start, entry_goal, [library.width]])
            mean = self._curvature.mean_path(self._curvature.value_and_data(np.ravel(torque), entry_params)[1])
            moved = self._retargeted(torque, mean, entry_goal, goal)
            if np.any(velocity):
                moved = [braked for candidate in moved for braked in
                         braked_torques(model.body, model.h, model.H, candidate, velocity, brake_durations(model.duration), mean)]
            candidates += moved
        return candidates

    def _drift(self, start, goal, width) -> float:
        """How far (m) the start's motion alone (zero commands) carries the hand within the horizon."""
        free = self.problem.trajectory(tau=np.zeros(self.model.H * self.model.n), s0=start, goal=goal, width=width)
        return float(np.max(np.linalg.norm(np.asarray(free["ee_mean"]).T - free["ee_mean"][:, 0].full().T, axis=1)))

    def _searched_guesses(self, start, goal, width, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The minimum-jerk guesses a cold solve without a reach library runs: all for 'all', a nonlinear body
        or a goal beyond ``narrow_ratio`` widths; otherwise the one of lowest objective."""
        guesses = self._cold_guesses(start, goal, self.options.n_starts, goal_q)
        if self.options.cold_search == "all" or not self.model.body.is_linear or self._narrow(start, goal, width):
            return guesses
        params = np.concatenate([start, goal, [width]])
        return [min(guesses, key=lambda guess: self._objective(guess, params))]

    def _narrow(self, start, goal, width) -> bool:
        """True when the goal is farther than ``narrow_ratio`` widths from the start's end-effector position."""
        position = self._kinematics(start[: self.model.n])[0].ravel()
        return bool(np.linalg.norm(goal - position) > self.options.narrow_ratio * width)

    def _cold_guesses(self, start, goal, count: int, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """Minimum-jerk reaches to ``goal_q`` (n,), the inverse-kinematics solution from the start (computed
        when None), ``count`` durations."""
        model = self.model
        goal_q = model.body.inverse_kinematics(goal, start[: model.n]) if goal_q is None else goal_q
        return list(minimum_jerk_torques(model.body, model.h, model.H, start, goal_q, guess_durations(model.duration, count),
                                         self._linear_dynamics))

    def _objective(self, torque: np.ndarray, params: np.ndarray) -> float:
        """J (or J normalised, for comparisons at fixed parameters) of torques (H, n)."""
        if self._curvature is not None:
            return self._curvature.value(np.ravel(torque), params)
        n2, d = self.model.state_size, self.model.d
        return self.problem.objective_value(torque, params[:n2], params[n2:n2 + d], params[-1])

    def _solve_from(self, guesses, start, goal, width, t_begin: float, max_wall_time: float | None,
                    until_converged: bool = False) -> Plan:
        """The best plan from the guesses (each (H, n)), solved in turn; ``until_converged``: stop at the
        first whose solve converges ('solved') within the limits and ends at the goal (later guesses are
        fallbacks). A solve that stalled ('solved_acceptable', along a redundant arm's flat directions) does not
        stop the search: on 200 cold franka_rest problems 5 library starts did, one of them 6.4e-6 above the plan
        of the full search (benchmarks/cold_quality.py, problem 175)."""
        deadline = np.inf if max_wall_time is None else t_begin + max_wall_time
        params = np.concatenate([start, goal, [width]])
        best = None
        iterations = 0
        # The Newton systems have a few hundred unknowns: one BLAS thread solves them fastest, and a
        # multi-threaded BLAS on a busy machine waits for cores (measured several times slower).
        with self._blas:
            for guess in guesses:
                if time.perf_counter() > deadline and best is not None:
                    break
                candidate = self._run_solver(guess, params, deadline)
                iterations += candidate.nit
                if not np.isfinite(candidate.x).all() or not np.isfinite(candidate.fun):
                    candidate = SolverResult(guess, self.problem.objective_value(guess, start, goal, width)
                                             / self.problem.normaliser(width),
                                             Status.FAILED, "solver returned a non-finite plan; returning the initial guess",
                                             candidate.nit, np.inf)
                # The plan within the limits with the lowest objective wins, whatever its status: a start that
                # stalls short of the tolerances can still be far better than one that converged on the
                # zero-reward plateau (seen on the Panda), and the status then says it did not converge.
                if best is None or _rank(candidate) < _rank(best):
                    best = candidate
                if until_converged and best.status == Status.SOLVED and self._ends_at_goal(best.x, params):
                    break
        evaluation = None if best.local_model is None else (best.fun, best.local_model[1])
        plan = self._make_plan(best.x, params, evaluation, status=best.status, success=best.success, message=best.message,
                               solve_time=time.perf_counter() - t_begin, iterations=iterations)
        self._last_solution = self._solution_of(best, plan.torque)
        return plan

    def _ends_at_goal(self, torque: np.ndarray, params: np.ndarray) -> bool:
        """True when the mean end effector of torques (H, n) ends within the goal width of the goal (a converged
        plan can rest on the zero-reward plateau instead)."""
        model, curvature = self.model, self._curvature
        n2, d = model.state_size, model.d
        q_end = curvature.mean_path(curvature.value_and_data(np.ravel(torque), params)[1])[-1, : model.n]
        end = np.asarray(model.body.kinematics_function(q_end)[0]).ravel()
        return bool(np.linalg.norm(end - params[n2:n2 + d]) <= params[-1])

    def _make_plan(self, torque, params, evaluation: tuple | None = None, **fields) -> Plan:
        """The Plan of torques (H, n); ``evaluation`` = (f, data): the Newton method's own evaluation at them, from
        which an arm's belief is taken without evaluating again (about 4 ms of a Panda solve)."""
        n2, d = self.model.state_size, self.model.d
        start, goal, width = params[:n2], params[n2:n2 + d], params[-1]
        curvature = self._curvature
        if curvature is None or not curvature.carries_belief:  # a point mass's expanded rollout is cheap
            return self.problem.make_plan(torque, start, goal, width, **fields)
        f, data = evaluation if evaluation is not None else curvature.evaluate(np.ravel(torque), params)[::2]
        return self.problem.make_plan(torque, start, goal, width, belief=curvature.trajectory(data),
                                      objective=f * curvature.normaliser(width), **fields)

    def _run_solver(self, guess: np.ndarray, params: np.ndarray, deadline: float) -> SolverResult[np.ndarray]:
        """One solve from torques guess (H, n) until ``deadline`` (perf_counter, s): x the torques (H, n),
        fun the normalised objective."""
        if self._curvature is None:
            return self._run_ipopt(guess, params, deadline)
        curvature = self._curvature
        value = (lambda x: curvature.value_and_data(x, params)) if curvature.cheap_value else None
        result = newton_minimize(lambda x: curvature.evaluate(x, params), curvature.hessian, np.ravel(guess),
                                 *self._torque_bounds, tolerance=self._tolerance,
                                 max_iterations=self._max_iterations, secant=not curvature.exact,
                                 hessian_refresh=1 if curvature.exact else self.options.hessian_refresh,
                                 constraints=self._limits.for_newton(curvature) if self._limits.active else None,
                                 constraint_tolerance=LIMIT_TOLERANCE, expired=lambda: time.perf_counter() > deadline,
                                 value=value)
        result.x = result.x.reshape(self.model.H, self.model.n)
        return result

    def _run_ipopt(self, guess: np.ndarray, params: np.ndarray, deadline: float) -> SolverResult[np.ndarray]:
        solver = self._ipopt
        self._deadline.time = deadline
        result = solver(x0=np.ravel(guess), p=params)
        stats = solver.stats()
        status = ipopt_status(stats, self._deadline)
        torque = np.asarray(result["x"]).reshape(self.model.H, self.model.n)
        return SolverResult(torque, float(result["f"]), status, stats["return_status"], int(stats.get("iter_count", 0)), np.nan)


@dataclass(eq=False)
class _LastSolution:
    """A converged point-mass plan's torques (H, n), the Cholesky factor of its solve's last Newton step and the
    evaluation at the plan: d tau*/d goal = -∇²f⁻¹ ∂²f/∂tau∂goal by the implicit function theorem (about 0.05 ms),
    computed when a warm start from the plan asks for it (:meth:`Planner._predicted`), not after every solve."""

    torque: np.ndarray
    factor: tuple
    data: object
    sensitivity: np.ndarray | None = None
    """d tau*/d goal (H·n, d) once computed."""


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
