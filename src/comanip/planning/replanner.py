"""Replanning at a controller's rate: the real-time iteration of model-predictive control on the reach problem.

A control loop replans every cycle from the state it measures. A :class:`Replanner` does it on a budget:

1. the previous plan's torques are moved to the current time (:func:`shifted_torques`: a cycle of any length,
   not only whole model steps);
2. from them and the measured state, one Newton iteration every cycle (the real-time iteration), then more up to a
   fixed number (``iterations``) or while they fit a wall budget (``max_wall_time``, every cost of the cycle
   included: the shift, the checks, the evaluation at the shifted plan and the iterations; a further iteration
   starts only when the longest of the recent iterations would still fit, a prepared cycle's first iteration counted
   with its preparation). The first iteration runs even where
   it does not fit the budget, and the cycle then overruns it (its ``wall_time`` says by how much): a cycle that
   stopped before it would send the shifted plan, and a loop of such cycles never converges along the loop;
3. the best plan comes back as a :class:`Replan` whose ``status`` says how the iterations stand
   (:class:`~comanip.optim.Progress`: 'converged', 'converging', 'not_contracting'). The point a cycle's last
   iteration accepts is evaluated value-only: its gradient (a fifth of a Panda cycle) serves only the status and
   the plan's belief, so it is evaluated when one of those is first read, after the loop has sent tau_0;
4. after sending tau_0, the loop may call :meth:`Replanner.prepare`: the preparation phase of the next cycle (acados'
   RTI split into preparation and feedback). It predicts the state the next cycle will measure (the body's step
   under tau_0 for the cycle's length), shifts the plan to that time, and assembles and factors the Hessian there
   (on an arm most of a cycle's work). The next cycle's first iteration then steps with that factor and the gradient at
   the state it measures, so that between the measurement and tau_0 there is one evaluation, a back-substitution
   and the line search. The gradient is exact, so the optimum is unchanged; only the first step's curvature is
   that of the predicted state (exact where the prediction is, as without motor noise). A cycle whose goal or
   width moved, or that does not follow the prepared plan, assembles its own.

What a solve sets up once per planner (the compiled terms, the torque bounds, the joint limits) the replanner
reuses; what a full solve redoes every time (the start policy's candidates, the reachability witness by inverse
kinematics) runs here only when the goal moves: the witness from the last one, and the shifted plan competes with
itself moved onto the new goal and with fresh minimum-jerk reaches to it. The first plan of a loop is a full
solve (:meth:`Replanner.first_plan`), made before the loop's budget applies. The scheme is that of acados' SQP_RTI
and of OCS2 and Crocoddyl's model-predictive control: one or a few iterations per cycle from the previous solution,
so that the iterations converge along the loop rather than within a cycle.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable, Protocol

import numpy as np

from comanip.arguments import as_count, as_nonnegative, as_optional_positive
from comanip.optim import Evaluation, Progress, SolverResult, contraction, progress_of
from comanip.optim.hessian_models import PreparedHessian
from comanip.optim.newton_loop import never
from comanip.planning.newton_reach_solver import NewtonReachSolver
from comanip.planning.plan import Plan, PlanStatus, with_reach_check
from comanip.planning.planner import Planner
from comanip.planning.reach_parameters import ReachParameters

RECENT_CYCLES = 50
"""Cycles over which a budgeted replanner remembers its times per Newton iteration."""
RESERVE_QUANTILE = 1.0
"""The quantile of the recent times per iteration that a budgeted cycle reserves for its next iteration: the longest,
so that a further iteration starts only where the slowest of the recent ones would still fit (an arm's iteration
takes longer the more joint limits bind; a lower quantile lets the cycles that meet such an iteration overrun). A stalled
iteration (the process descheduled) then holds the cycles to their one iteration until it ages out, RECENT_CYCLES
cycles later."""


def shifted_torques(torque: np.ndarray, steps: float) -> np.ndarray:
    """A plan's torques (H, n) moved ``steps`` (≥ 0, any fraction) model steps later: the torque over each step is
    the mean of the plan's piecewise-constant torque over that step moved by steps·h, so the new plan applies
    from its start what the old one applied from steps·h on; past the old plan's end its last torque holds.
    Whole steps drop the first ``steps`` rows."""
    H = len(torque)
    whole = min(int(np.floor(steps)), H)
    fraction = steps - whole if whole < H else 0.0
    padded = np.concatenate([torque, np.repeat(torque[-1:], whole + 1, axis=0)])
    return (1.0 - fraction) * padded[whole:whole + H] + fraction * padded[whole + 1:whole + 1 + H]


@dataclass(frozen=True)
class CycleOutcome:
    """How a cycle's iterations stand (:attr:`Replan.status` and its neighbours read it)."""

    status: Progress
    solver_status: str
    message: str
    optimality: float = np.nan


@dataclass
class Replan:
    """One cycle's plan and how its iterations stand. Shapes: H steps, n degrees of freedom.

    A cycle whose last Newton iteration left the gradient at its plan unevaluated (a one-iteration cycle: only the
    status reads it) evaluates it on the first read of :attr:`status`, :attr:`solver_status`, :attr:`message`,
    :attr:`optimality` or :attr:`plan`, so that a loop sends tau_0 first; :attr:`wall_time` is the cycle's up to its
    return."""

    torque: np.ndarray
    """The plan's commands tau_i (H, n), N·m (N for point masses); tau_0 is the one to send now."""
    params: ReachParameters
    """The cycle's start (the measured state), goal and width."""
    iterations: int
    """Newton iterations of the cycle."""
    wall_time: float
    """Wall time of the cycle (s): everything from the call to the return."""
    judge: Callable[[], CycleOutcome] = field(repr=False, compare=False)
    """Makes :attr:`outcome` on first use."""
    start_optimality: float = np.nan
    """max |gradient of the Lagrangian| of the normalised objective at the shifted plan the cycle started from (NaN
    where not known)."""
    goal_q: np.ndarray | None = None
    """An arm's joint position (n,) within its limits that reaches the goal (the reachability witness); None for point
    masses."""
    build_plan: Callable[[], Plan] | None = field(default=None, repr=False, compare=False)
    """Makes :attr:`plan` on first use (a loop that sends only tau_0 never pays for the belief's rollout)."""

    @cached_property
    def outcome(self) -> CycleOutcome:
        """How the cycle's iterations stand (evaluated on first use)."""
        return self.judge()

    @property
    def status(self) -> Progress:
        """'converged' (the plan is optimal for the cycle's state), 'converging' (the budget ran out with the
        first-order optimality lower than at the shifted plan), 'not_contracting' (neither: the iterations did not
        lower the optimality, the solve failed, or the goal is out of reach)."""
        return self.outcome.status

    @property
    def solver_status(self) -> str:
        """The solver's word for how the cycle ended (:class:`~comanip.optim.Status`: 'solved', 'solved_acceptable',
        'max_iterations', 'max_wall_time', 'failed', ...), or 'unreachable' for a goal out of an arm's reach."""
        return self.outcome.solver_status

    @property
    def message(self) -> str:
        """The solver's status in words."""
        return self.outcome.message

    @property
    def optimality(self) -> float:
        """max |gradient of the Lagrangian| of the normalised objective at the plan (NaN where not known)."""
        return self.outcome.optimality

    @property
    def success(self) -> bool:
        """True when the cycle's iterations converged or contract."""
        return self.status in (Progress.CONVERGED, Progress.CONVERGING)

    @property
    def contraction(self) -> float:
        """``optimality`` over ``start_optimality`` (< 1: the cycle's iterations contracted; NaN where unknown)."""
        return contraction(self.start_optimality, self.optimality)

    @cached_property
    def plan(self) -> Plan:
        """The cycle's :class:`Plan` (its belief rolled out from the cycle's state; its status the solver's)."""
        return self.build_plan()

    @classmethod
    def of_plan(cls, plan: Plan, goal_q: np.ndarray | None = None, wall_time: float | None = None) -> "Replan":
        """The Replan of a full solve's :class:`Plan` (converged or not by its own status)."""
        outcome = CycleOutcome(Progress.CONVERGED if plan.converged else Progress.NOT_CONTRACTING, plan.status, plan.message)
        replan = cls(plan.torque, ReachParameters(plan.start, plan.goal, plan.width), plan.iterations,
                     plan.solve_time if wall_time is None else wall_time, lambda: outcome, goal_q=goal_q)
        replan.plan = plan  # the cached property's value
        return replan


@dataclass(frozen=True)
class Preparation:
    """What :meth:`Replanner.prepare` made for the cycle after ``previous``."""

    previous: Replan
    hessian: PreparedHessian
    wall_time: float
    """Its wall time (s): an evaluation, the Hessian's assembly and its factorisation, most of what an iteration on a
    Hessian of its own costs."""


class Replanning(Protocol):
    """What a control loop asks of its replanning (:func:`comanip.execution.execute_receding_horizon`): the planner,
    a first plan, a plan for each cycle from the last one, and the preparation of the next cycle after tau_0 is
    sent."""

    planner: Planner

    def first_plan(self, start, goal, width: float | None = None) -> Replan:
        """The loop's first plan from start (nx,) to goal (d,) of width w (m), before any budget applies."""

    def replan(self, previous: Replan, state, elapsed: float, goal=None, width: float | None = None) -> Replan:
        """The cycle's plan from the measured state (nx,), ``elapsed`` seconds after ``previous`` started."""

    def prepare(self, replan: Replan, elapsed: float) -> float:
        """Work for the cycle expected ``elapsed`` seconds after ``replan`` started, done after its tau_0 is sent; the
        wall time it took (s)."""


class Replanner:
    """Replans a reach of one planner once per control cycle on a budget (module docstring).

    Args:
        planner: a built :class:`Planner` with the Newton method (``SolverOptions.method="newton"``).
        iterations: Newton iterations per cycle (≥ 1); None: as many as the wall budget allows, or, without one, until
            the solve converges (the planner's iteration limit).
        max_wall_time: wall budget of a cycle (s), every cost included; None: no budget. With both, a cycle stops at
            whichever comes first, after its first iteration.

    >>> replanner = Replanner(comanip.Planner(comanip.presets.load("franka_rest")), iterations=1)
    >>> replan = replanner.first_plan(start, goal, 0.02)
    >>> replanner.prepare(replan, elapsed=0.01)                           # after sending replan.torque[0]
    >>> replan = replanner.replan(replan, measured_state, elapsed=0.01)   # every cycle; send replan.torque[0]
    """

    def __init__(self, planner: Planner, iterations: int | None = 1, max_wall_time: float | None = None):
        if not isinstance(planner, Planner):
            raise ValueError(f"planner must be a comanip.Planner, got {type(planner).__name__}")
        if not isinstance(planner.solver, NewtonReachSolver):
            raise ValueError(f"real-time replanning runs the Newton method in stages; this planner uses method "
                             f"{planner.options.method!r}, build it with SolverOptions(method='newton')")
        self.planner = planner
        self.iterations = as_count("iterations", iterations, optional=True, unit="Newton iterations")
        self.max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")
        self._iteration_limit = self.iterations if self.iterations is not None else planner.solver.max_iterations
        self._iteration_times: list[float] = []
        """Seconds per Newton iteration that assembles its own Hessian, one for each of the last RECENT_CYCLES budgeted
        cycles (0 for a cycle without iterations, so that old times age out): an iteration on a prepared Hessian costs
        less, and would under-reserve for the next, so a prepared cycle counts its preparation with it."""
        self._preparation: Preparation | None = None
        """The last :meth:`prepare`'s work, for the next cycle (used once)."""
        self._step: tuple[float, Callable] | None = None
        """(cycle length (s), the body's step of that length), the last one :meth:`prepare` predicted with."""

    def first_plan(self, start, goal, width: float | None = None) -> Replan:
        """The loop's first plan: a full solve from start (nx,) to goal (d,) of width w (m; the model's when None)."""
        plan = self.planner.solve(start, goal, width)
        goal_q = self.planner.goal_joints(ReachParameters(plan.start, plan.goal, plan.width), near=plan.mean[-1, : self.planner.model.n])
        return Replan.of_plan(plan, goal_q)

    def replan(self, previous: Replan, state, elapsed: float, goal=None, width: float | None = None) -> Replan:
        """The cycle's plan from the measured ``state`` (nx,), ``elapsed`` (s, ≥ 0) after ``previous`` started, to
        ``goal`` (d,, m) of width ``width`` (m); both default to the previous plan's. Never raises for a failed solve:
        the status says how it went, and the plan is the best the cycle found (the shifted plan at worst)."""
        began = time.perf_counter()
        if not isinstance(previous, Replan):
            raise ValueError(f"previous must be the Replan of the last cycle (first_plan or replan), got {type(previous).__name__}")
        elapsed = as_nonnegative("elapsed", elapsed, "s")
        planner, model = self.planner, self.planner.model
        goal = previous.params.goal if goal is None else goal
        width = previous.params.width if width is None else width
        params = ReachParameters(*planner.check_inputs(state, goal, width))
        preparation, self._preparation = self._preparation, None
        guess = shifted_torques(previous.torque, elapsed / model.h)
        goal_q = previous.goal_q
        moved = not (np.array_equal(params.goal, previous.params.goal) and params.width == previous.params.width)
        if preparation is not None and (preparation.previous is not previous or moved):
            preparation = None
        prepared = None if preparation is None else preparation.hessian
        if goal_q is not None and moved:
            goal_q = planner.goal_joints(params, near=goal_q)
            if not planner.reaches(goal_q, params):
                return self._unreachable(guess, params, goal_q, began)
        if moved:
            planned = ReachParameters(params.start, previous.params.goal, previous.params.width)
            guess = planner.starts.moved_onto_goal(guess, planned, params, goal_q)
        solver = planner.solver
        with solver.blas:
            # the real-time iteration: one iteration every cycle, whatever the budget, so that the iterations converge
            # along the loop; more while a recent iteration's time still fits. The gradient at the point a cycle's
            # last iteration accepts serves only its status: it is evaluated when the status is read
            solve = solver.newton_solve(guess, params, np.inf, solver.curvature, prepared)
            set_up = time.perf_counter()
            result = solve.advance(1, gradient_at_end=self._may_iterate_again(began, set_up))
            first_done = time.perf_counter()
            if self._iteration_limit > 1 and not solve.finished:
                solve.expired = self._expired(began, self._first_iteration_time(set_up, first_done, preparation))
                result = solve.advance(self._iteration_limit, gradient_at_end=False)
        ended = time.perf_counter()
        if self.max_wall_time is not None:
            if result.nit > 1:
                time_per_iteration = (ended - first_done) / (result.nit - 1)
            else:
                time_per_iteration = self._first_iteration_time(set_up, first_done, preparation) if result.nit else 0.0
            self._iteration_times = [*self._iteration_times[1 - RECENT_CYCLES:], time_per_iteration]
        finite = solver.finite(result, guess, params)
        torque = np.reshape(finite.x, (model.H, model.n))
        solver.count_solving_time(ended - began)
        judge, build_plan = _deferred(solver, solve, result, finite, guess, params, torque, ended - began)
        return Replan(torque, params, result.nit, ended - began, judge, result.start_optimality, goal_q, build_plan)

    def prepare(self, replan: Replan, elapsed: float, state=None) -> float:
        """The preparation phase of the cycle expected ``elapsed`` (s, ≥ 0) after ``replan`` started, to run once its
        tau_0 is sent (module docstring, step 4): the Hessian at the plan shifted by ``elapsed`` from the state the
        next cycle is expected to measure, assembled and factored for :meth:`replan`'s first iteration when its
        ``previous`` is ``replan`` and its goal and width are ``replan``'s. ``state`` (nx,): that expected state (a
        robot's own prediction); None: the body's step from ``replan``'s start under tau_0 for ``elapsed``. Returns
        its wall time (s). A replanner without a budget (``iterations=None`` and no ``max_wall_time``) prepares
        nothing: its cycles converge, and a prepared first step would only move their plans within the tolerance.

        >>> replan = replanner.replan(replan, state, elapsed=0.01)
        >>> send(replan.torque[0]); replanner.prepare(replan, 0.01)
        """
        began = time.perf_counter()
        if not isinstance(replan, Replan):
            raise ValueError(f"replan must be a Replan of this replanner (first_plan or replan), got {type(replan).__name__}")
        elapsed = as_nonnegative("elapsed", elapsed, "s")
        planner = self.planner
        if state is not None:
            state = planner.check_inputs(state, replan.params.goal, replan.params.width)[0]
        self._preparation = None
        if self.iterations is None and self.max_wall_time is None:
            return time.perf_counter() - began
        with planner.solver.blas:
            if state is None:
                if self._step is None or self._step[0] != elapsed:
                    self._step = (elapsed, planner.model.body.step_function(elapsed))
                state = np.asarray(self._step[1](replan.params.start, replan.torque[0])).ravel()
            params = ReachParameters(state, replan.params.goal, replan.params.width)
            hessian = planner.solver.prepared_hessian(shifted_torques(replan.torque, elapsed / planner.model.h), params)
        wall_time = time.perf_counter() - began
        if hessian is not None:
            self._preparation = Preparation(replan, hessian, wall_time)
        return wall_time

    @staticmethod
    def _first_iteration_time(set_up: float, first_done: float, preparation: Preparation | None) -> float:
        """What a cycle's first iteration, from ``set_up`` to ``first_done`` (perf_counter, s), would have cost on a
        Hessian of its own: with the preparation's time where it stepped on a prepared one."""
        return first_done - set_up + (0.0 if preparation is None else preparation.wall_time)

    def _may_iterate_again(self, began: float, set_up: float) -> bool:
        """Whether a cycle that began at ``began`` and set up its solve by ``set_up`` (perf_counter, s) may run a second
        iteration: the iteration limit allows one and, on a budget, two of the recent iterations fit what is left of
        it (its first iteration then keeps its gradient, which the second starts from)."""
        if self._iteration_limit == 1:
            return False
        if self.max_wall_time is None or not self._iteration_times:
            return True
        reserve = float(np.quantile(self._iteration_times, RESERVE_QUANTILE))
        return set_up - began + 2 * reserve <= self.max_wall_time

    def _expired(self, began: float, first_iteration: float) -> Callable[[], bool]:
        """Whether the cycle that began at ``began`` (perf_counter, s) and whose first iteration would have taken
        ``first_iteration`` seconds on a Hessian of its own may start no more Newton iterations: past the budget's
        end less the RESERVE_QUANTILE of the recent times per iteration, this one's included, so that the cycle ends
        within its budget where an iteration fits in it (never, without a budget)."""
        if self.max_wall_time is None:
            return never
        reserve = float(np.quantile([*self._iteration_times, first_iteration], RESERVE_QUANTILE))
        deadline = began + self.max_wall_time - reserve
        return lambda: time.perf_counter() > deadline

    def _unreachable(self, guess: np.ndarray, params: ReachParameters, goal_q: np.ndarray, began: float) -> Replan:
        """The cycle of a goal out of the arm's reach: the shifted plan, status 'not_contracting'."""
        planner = self.planner
        message = (f"goal {np.round(params.goal, 4).tolist()} m is out of the {planner.model.body.name}'s reach within its "
                   f"joint limits (goal width {params.width} m); the shifted plan is kept")
        wall_time = time.perf_counter() - began

        def build_plan() -> Plan:
            return planner.solver.make_plan(guess, params, status=PlanStatus.UNREACHABLE, success=False, message=message,
                                            solve_time=wall_time, iterations=0)

        outcome = CycleOutcome(Progress.NOT_CONTRACTING, PlanStatus.UNREACHABLE, message)
        return Replan(guess, params, 0, wall_time, lambda: outcome, goal_q=goal_q, build_plan=build_plan)


def _deferred(solver: NewtonReachSolver, solve, result: SolverResult, finite: SolverResult, guess: np.ndarray,
              params: ReachParameters, torque: np.ndarray, solve_time: float) -> tuple[Callable, Callable]:
    """A cycle's outcome and plan, computed when first asked (:class:`Replan`'s ``judge`` and ``build_plan``): both
    read the cycle's result with the gradient at its plan evaluated, once (the solve keeps its completed result)."""
    def completed() -> SolverResult:
        if finite is not result:  # the solver's plan was not finite: the guess, failed
            return finite
        with solver.blas:
            return solver.finite(solve.completed(), guess, params)

    def judge() -> CycleOutcome:
        final = completed()
        return CycleOutcome(progress_of(final), final.status, final.message, final.optimality)

    def build_plan() -> Plan:
        final = completed()
        data = None if final.local_model is None else final.local_model.data
        evaluation = None if data is None else Evaluation(final.fun, None, data)
        return with_reach_check(solver.make_plan(torque, params, evaluation, status=final.status, success=final.success,
                                                 message=final.message, solve_time=solve_time, iterations=final.nit))

    return judge, build_plan
