"""A regularised Newton method for smooth problems with inequality constraints (active-set SQP):

    min f(x)  subject to  lb ≤ x ≤ ub  and  c(x) ≤ 0.

It is meant for problems with a few hundred unknowns, a dense Hessian that is cheap to assemble, and
constraints that bind at a handful of rows at most, where a general NLP solver spends more per iteration on its
own machinery than the Hessian costs; so the iteration is written out here:

Solver quantities are named as in ``docs/notation.md``: ``hessian`` (∇²f, not the horizon H), the
``working`` set of constraint rows (not the covariance W), ``merit_weight`` (not the mean mu) and
``multipliers`` (not the effort weight nu). The factorisation, line search, status and result are those
of :mod:`comanip.optim`; the iteration is :func:`comanip.optim.newton_loop.newton_iterate`, the
Hessian strategies :mod:`comanip.optim.hessian_models`, the working set :mod:`comanip.optim.active_set`.

- Working set: the constraints within ``margin`` of binding (c_j > -margin), bounds included as rows of
  ±I. Without any, the step is the Newton step.
- Direction: minimise the quadratic model gᵀp + ½ pᵀ(hessian + delta·s·I)p subject to the linearised working
  constraints c_W + A_W p = 0, by one Cholesky factorisation and a Schur complement on the few working rows;
  a constraint that is not violated beyond ``constraint_tolerance`` and gets a negative multiplier leaves
  the working set and the step is recomputed. s = max |diag hessian|; delta is 0 whenever the hessian is
  positive definite, otherwise the smallest of delta_last/3, 8·delta_last/3, ... (1e-4 the first time) for
  which the factorisation succeeds (IPOPT's inertia correction, :func:`comanip.optim.growing_shifts`).
- Step: backtracking, alpha = 1, 1/2, ..., on the l1 merit f + merit_weight Σ max(0, c - constraint_tolerance/2)
  (merit_weight ≥ 2 max multiplier) until it decreases by 1e-4 of its directional derivative (Armijo,
  :func:`comanip.optim.backtrack`); a trial that raises the violation gets a second-order correction first.
- Secant correction (``secant=True``, for approximate Hessians): C is updated after every step s with
  the symmetric rank-one formula C += r rᵀ / (rᵀ s), r = y - (hessian + C) s, y the change of gradient, and
  hessian + C is used in its place. It learns the curvature the approximation misses along the directions
  the iteration actually moves in (the iterations saved: docs/results/speed.md). Where hessian + C needs a
  shift delta ≥ 0.1 (``CORRECTED_SHIFT_LIMIT``), C is dropped (reset to zero) and the hessian alone is factored,
  shifted as it needs: a large shift shrinks only a third per iteration and would hold the steps short long after.
- Chord steps (exact Hessians, ``secant=False``): while no constraint is in the working set and the last step
  cut max |∇f| at least tenfold, the next step reuses that step's factorisation instead of evaluating and
  factoring a new Hessian (Kelley 2003, sec. 5.4: the chord method); a step that cuts it less, or fails the
  line search, brings a fresh Hessian back. It trades Hessians and factorisations for cheap iterations; the
  optimum is the same.
- Lazy assembly (approximate Hessians, ``hessian_refresh`` k > 1): the hessian is assembled only every k-th
  iteration, and whenever the last step was shortened by the line search or taken with constraints in the
  working set (there the model had been wrong, or the iterate follows a limit, where a kept hessian ends the
  solve at a worse point); in between the last one is kept and the secant corrections, updated against it,
  carry the change of curvature (an update costs far less than an assembly). The Cholesky factor of the last factored matrix then takes those rank-one updates
  by the Woodbury identity, when it needed no shift and stays positive definite (checked by the inertia of the small
  capacitance matrix), instead of a new factorisation. The gradient is evaluated at every iterate, so the
  convergence test and the optimum are those of k = 1.
- A last iteration without the gradient (``NewtonSolve.advance(..., gradient_at_end=False)``): the iteration that
  spends the budget evaluates its trials value-only and accepts its point without the gradient, which only the
  result's optimality would read; :meth:`~comanip.optim.NewtonSolve.completed`, or a further ``advance``, evaluates it.
- A prepared first Hessian (``prepared``): the first step uses a Hessian and factor made ahead of the solve at a
  point near its start (a real-time iteration's preparation phase, run while the controller executes the last
  command); the gradient is the start's own, so the optimum is unchanged and only the first step's curvature is
  approximate. A failed line search assembles the Hessian at the start again.
- Restoration: when no step decreases the merit while a constraint is violated, the least-norm step onto
  the violated constraints' linearisation is taken if it halves the violation.
- Recovery: when no step decreases the merit otherwise, the secant corrections are dropped and the step is
  recomputed with delta ≥ 1e-3, then 1e-2, 1e-1 (turning it towards steepest descent), before giving up.
- Convergence: max |∇f + A_Wᵀ lambda| ≤ tolerance with every constraint violated by at most
  ``constraint_tolerance`` ('solved'). If the merit cannot be decreased any more in floating point, the
  point is 'solved_acceptable' when the constraints are met and that gradient is below 1e-4 (or 100 ×
  tolerance, if larger). It is 'solved_acceptable' too when f has decreased by less than 1e-8 |f| over the
  last five iterations with the gradient below 1e-4 and the constraints met: along the nearly flat
  directions of a nearly singular problem an approximate Hessian converges linearly and slowly, while the iterate
  stopped changing long before.

f must be finite at x0; a trial point where f is not finite is treated as a failed trial.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from comanip.arguments import as_count
from comanip.optim.active_set import NO_MULTIPLIERS, NO_ROWS, ConstraintSet, Iterate, constrained_step, restoration_step
from comanip.optim.evaluation import Evaluation
from comanip.optim.factorisation import CholeskyFactor
from comanip.optim.hessian_models import ExactHessian, PreparedHessian, SecantHessian
from comanip.optim.line_search import Backtracked, backtrack
from comanip.optim.newton_loop import NewtonMethod, NewtonSolve, Stop, never
from comanip.optim.result import LocalModel, SolverResult
from comanip.optim.status import BUDGET_SPENT, Status

_BACKTRACKS = 30
"""Step lengths tried by one line search."""
_RESTORATION_TRIALS = 4
"""Step lengths tried by a restoration step (1 to 1/8)."""
_RECOVERIES = 3
"""Attempts after a failed line search (each with a stronger shift, :mod:`comanip.optim.hessian_models`)."""
_STALL_WINDOW, _STALL_DECREASE, _STALL_GRADIENT = 5, 1e-8, 1e-4
"""Iterations, relative decrease of f over them, and gradient for the stagnation test."""
_NO_STEP = Backtracked(0.0, None)
"""A line search that accepted no step length."""


def newton_minimize(evaluate: Callable[[np.ndarray], Evaluation],
                    hessian: Callable[[Any], np.ndarray], x0: np.ndarray, lb: np.ndarray, ub: np.ndarray, *,
                    max_iterations: int, **options) -> SolverResult[np.ndarray, LocalModel]:
    """Minimise f over the box [lb, ub] and c(x) ≤ 0 from x0, in at most ``max_iterations`` iterations (each evaluates
    the Hessian, except a last one that only finds the point converged); the arguments and the result are those of
    :func:`newton_solve`."""
    return newton_solve(evaluate, hessian, x0, lb, ub, **options).advance(max_iterations)


def newton_solve(evaluate: Callable[[np.ndarray], Evaluation],
                 hessian: Callable[[Any], np.ndarray], x0: np.ndarray, lb: np.ndarray, ub: np.ndarray, *,
                 tolerance: float, secant: bool = False,
                 constraints: Callable[[np.ndarray, Any], tuple[np.ndarray, Callable]] | None = None,
                 constraint_tolerance: float = 1e-6, margin: float = 1e-3,
                 expired: Callable[[], bool] = never,
                 value: Callable[[np.ndarray], Evaluation] | None = None,
                 hessian_refresh: int = 1, prepared: PreparedHessian | None = None) -> NewtonSolve[SQPState]:
    """The solve of f over the box [lb, ub] and c(x) ≤ 0 from x0, to run in stages (:class:`NewtonSolve`: its
    ``advance(max_iterations)`` gives the result); f is evaluated at x0 here.

    Args:
        evaluate: x (N,) -> its :class:`~comanip.optim.Evaluation` (f, grad f (N,), data); ``data`` is handed to
            ``hessian`` and ``constraints``.
        hessian: data -> ∇²f (N, N), symmetric (the solver does not modify it).
        x0: start (N,), projected onto the box; lb, ub: bounds (N,), ±inf allowed.
        tolerance: on max |gradient of the Lagrangian|.
        secant: add symmetric rank-one corrections to an approximate Hessian.
        constraints: (x, data) -> (c (m,), rows), rows(indices) -> dc_indices/dx (len(indices), N); None
            for none. Entries of c may be -inf (no constraint).
        constraint_tolerance: largest violation a solution may keep (units of c).
        margin: constraints with c > -margin are in the working set.
        expired: called between evaluations; True stops with status 'max_wall_time'.
        value: x -> its Evaluation without the gradient, for line-search trials when that is much cheaper than
            ``evaluate`` (``data`` then only needs what ``constraints`` reads); ``evaluate`` runs once a trial
            is accepted. None: trials use ``evaluate``.
        hessian_refresh: with ``secant``, assemble ``hessian`` every this many iterations (and after any step that
            was not a full, unconstrained one), keeping the last one with updated secant corrections in between; 1:
            every iteration. Must be 1 without ``secant`` (an exact Hessian is assembled at every iteration, chord
            steps apart).
        prepared: the first step's Hessian and its factor, made ahead of the solve at a point near x0
            (:func:`~comanip.optim.hessian_models.prepare_hessian`; a real-time iteration's preparation) in place of
            ``hessian`` at x0; None: assembled at x0.

    Results (of ``advance``):
        A :class:`~comanip.optim.SolverResult`: x the best point (N,), fun its f, nit the iterations,
        optimality max |∇f + A_Wᵀ multipliers| there, violation max(0, c) bounds included, local_model
        a :class:`~comanip.optim.LocalModel`: the factor of the last step's matrix and the evaluation's ``data`` at x.
    """
    if type(hessian_refresh) is not int or hessian_refresh != 1:
        hessian_refresh = as_count("hessian_refresh", hessian_refresh, unit="iterations")
    if hessian_refresh > 1 and not secant:
        raise ValueError(f"hessian_refresh must be 1 without secant corrections (an exact Hessian is assembled at "
                         f"every iteration), got {hessian_refresh}")
    hessians = SecantHessian(hessian, hessian_refresh, prepared) if secant else ExactHessian(hessian, prepared)
    method = ActiveSetNewton(evaluate, hessians, ConstraintSet(lb, ub, constraints), value, tolerance=tolerance,
                             constraint_tolerance=constraint_tolerance, margin=margin)
    x = np.array(x0, dtype=float) if method.problem.unbounded else np.clip(np.asarray(x0, dtype=float), lb, ub)
    start = evaluate(x)
    point = method.finite_point(x, start)
    if point is None:
        return NewtonSolve(None, None, final=SolverResult(x, start.f, Status.FAILED, "objective or gradient not finite at the start", 0, np.inf))
    state = SQPState(point, history=[point.f])
    method.place(state, point)
    return NewtonSolve(method, state, expired)


def _lagrangian_optimality(point: Iterate, working: np.ndarray, multipliers: np.ndarray) -> float:
    """max |∇f + A_Wᵀ multipliers| at the point, A_W the rows of the working set ``working``."""
    gradient = point.g + point.rows(working).T @ multipliers if len(working) else point.g
    return float(np.abs(gradient).max())


@dataclass(slots=True)
class SQPState:
    """The iterate and what the method remembers between iterations."""

    point: Iterate
    iterations: int = 0
    history: list[float] = field(default_factory=list)
    """f at every iterate, for the stagnation test."""
    merit_weight: float = 0.0
    recoveries: int = 0
    """Consecutive failed line searches at this iterate."""
    full_steps: bool = True
    """The last line search took the full step: evaluate the next full step with its gradient."""
    model_held: bool = False
    """The last step was a full step with no constraint in the working set."""
    stepped_with: CholeskyFactor | None = None
    """The factorisation of the last step taken (None when its matrix had secant updates since it was factored)."""
    free: bool = True
    """No constraint in the working set at the iterate."""
    optimality: float = np.inf
    """max |gradient of the Lagrangian| at the iterate, once known."""
    start_optimality: float = np.nan
    """``optimality`` at the start point, once known."""
    working: np.ndarray = field(default_factory=lambda: NO_ROWS)
    """The working set of the last direction computed."""
    multipliers: np.ndarray = field(default_factory=lambda: NO_MULTIPLIERS)
    """The working set's multipliers of the last direction computed."""
    repeat: bool = False
    """The pass retries the iteration (a chord step failed): it is not counted again."""
    gradient_at_step: bool = True
    """The point the pass accepts is evaluated with its gradient (False on the last pass of a budget whose caller
    does not need it: :meth:`ActiveSetNewton.last_iteration`)."""


@dataclass(slots=True)
class SQPDirection:
    """A step from the iterate, with the working set and multipliers it was computed under."""

    step: np.ndarray
    working: np.ndarray
    correct: Callable | None
    """c_W -> the least-H-norm move back onto the working set's linearisation (second-order correction)."""
    factor: CholeskyFactor | None
    """The factorisation the step was computed with (None when its matrix had secant updates since)."""
    chord: bool = False
    """Taken with an earlier iteration's factor."""


@dataclass
class ActiveSetNewton(NewtonMethod[SQPState, SQPDirection]):
    """The method of the module docstring for one problem: the hooks :func:`newton_iterate` calls."""

    evaluate: Callable
    hessians: ExactHessian | SecantHessian
    problem: ConstraintSet
    value: Callable | None
    tolerance: float
    constraint_tolerance: float
    margin: float

    def at(self, x: np.ndarray, evaluation: Evaluation) -> Iterate:
        return Iterate(x, evaluation.f, evaluation.gradient, evaluation.data, *self.problem(x, evaluation.data))

    def finite_point(self, x: np.ndarray, evaluation: Evaluation) -> Iterate | None:
        """The iterate at x, or None where f or an entry of its gradient (if evaluated) is not finite."""
        if not math.isfinite(evaluation.f):
            return None
        point = self.at(x, evaluation)
        return point if point.finite else None

    def iterations(self, state: SQPState) -> int:
        return state.iterations

    def begin(self, state: SQPState) -> None:
        self.complete(state)
        state.iterations += not state.repeat
        state.repeat, state.gradient_at_step = False, True

    def last_iteration(self, state: SQPState) -> None:
        """The point this pass accepts is evaluated value-only (its gradient, a full evaluation, waits for
        :meth:`complete`)."""
        state.gradient_at_step = False

    def place(self, state: SQPState, point: Iterate) -> None:
        """Makes ``point`` the iterate, with what the convergence test reads there: whether no constraint is in the
        working set, and then the Lagrangian's gradient, the gradient (NaN without it; a constrained point's is
        known once its direction has found the multipliers); the start's, once known."""
        state.point = point
        state.free = point.largest <= -self.margin
        state.optimality = point.steepest if state.free else np.inf
        if state.free and np.isnan(state.start_optimality):
            state.start_optimality = state.optimality

    def complete(self, state: SQPState) -> bool:
        """The gradient at an iterate accepted value-only."""
        point = state.point
        if point.g is not None:
            return False
        self.place(state, self.at(point.x, self.evaluate(point.x)))
        return True

    def converged(self, state: SQPState) -> Stop | None:
        """With no constraint in the working set the Lagrangian's gradient is the gradient, and a converged
        point needs no Hessian (the last iteration of a warm solve)."""
        return self._converged(state) if state.free else None

    def direction(self, state: SQPState) -> SQPDirection | Stop:
        point = state.point
        if state.free:
            chord = self.hessians.chord_factor(state.optimality, state.recoveries)
            if chord is not None:
                return SQPDirection(-chord.solve(point.g), NO_ROWS, None, chord, chord=True)
        factored = self.hessians.factor(point, state.recoveries, state.model_held)
        if isinstance(factored, Stop):
            state.optimality = np.inf
            return factored
        solve, factor = factored.solve, factored.factor
        if state.free:  # the Newton step; its optimality was tested in converged()
            step, multipliers, working, correct = -solve(point.g), NO_MULTIPLIERS, NO_ROWS, None
        else:
            step, multipliers, working, correct, state.optimality = constrained_step(
                solve, point.g, point.c, point.rows, self.margin, self.constraint_tolerance)
            if np.isnan(state.start_optimality):
                state.start_optimality = state.optimality
        state.working, state.multipliers = working, multipliers
        self.hessians.stepped(factor, state.optimality, state.free)
        if len(multipliers):
            state.merit_weight = max(state.merit_weight, 2 * float(np.max(multipliers)))
        return SQPDirection(step, working, correct, factor)

    def solved_along(self, state: SQPState, direction: SQPDirection) -> Stop | None:
        """With constraints in the working set, the Lagrangian's gradient is known once the direction has found the
        multipliers: the test of :meth:`converged` on it."""
        return None if state.free else self._converged(state)

    def globalise(self, state: SQPState, direction: SQPDirection) -> bool:
        """Armijo's rule on the l1 merit along the step; where it fails while a constraint is violated, the
        restoration step."""
        point = state.point
        searched = self._line_search(point, direction.step, direction.working, direction.correct,
                                     state.merit_weight, state.full_steps, state.gradient_at_step)
        alpha, accepted = searched.alpha, searched.accepted
        state.full_steps = alpha == 1.0
        if not direction.chord:
            state.model_held = alpha == 1.0 and len(direction.working) == 0
            if accepted is None and point.violation > self.constraint_tolerance:
                accepted = self._restore(point, state.gradient_at_step)
            elif accepted is not None:
                state.recoveries = 0
        if accepted is None:
            return False
        self.place(state, accepted)
        state.stepped_with = direction.factor
        state.history.append(accepted.f)
        return True

    def recover(self, state: SQPState, direction: SQPDirection) -> Stop | None:
        """A failed chord step: the iteration again with a fresh Hessian. Otherwise the quadratic model was wrong
        along this step: forget the secant corrections and regularise harder, then try again from the same
        point, up to ``_RECOVERIES`` times."""
        self.hessians.forget()
        if direction.chord:
            state.repeat = True
            return None
        if state.recoveries < _RECOVERIES:
            state.recoveries += 1
            return None
        return self._final_status(state)

    def result(self, state: SQPState, stop: Stop) -> SolverResult[np.ndarray, LocalModel]:
        """The result at the iterate. A solve its budget stopped at an iterate with constraints in the working set
        reports the Lagrangian's gradient there estimated with the last direction's multipliers (the exact ones need
        the next direction)."""
        point, optimality = state.point, state.optimality
        if stop.status in BUDGET_SPENT and not state.free:
            optimality = _lagrangian_optimality(point, state.working, state.multipliers) if point.g is not None else np.nan
        return SolverResult(point.x, point.f, stop.status, stop.message, state.iterations, optimality, point.violation,
                            LocalModel(state.stepped_with, point.data), state.start_optimality)

    def _converged(self, state: SQPState) -> Stop | None:
        """A stop when the point is a solution (module docstring, Convergence), else None."""
        point, optimality, history = state.point, state.optimality, state.history
        if point.violation > self.constraint_tolerance:
            return None
        if optimality <= self.tolerance:
            return Stop(Status.SOLVED, "gradient of the Lagrangian below tolerance")
        if len(history) > _STALL_WINDOW and optimality <= _STALL_GRADIENT \
                and history[-1 - _STALL_WINDOW] - point.f <= _STALL_DECREASE * abs(point.f):
            return Stop(Status.SOLVED_ACCEPTABLE, f"objective unchanged to {_STALL_DECREASE:g} over {_STALL_WINDOW} iterations")
        return None

    def _final_status(self, state: SQPState) -> Stop:
        """Why the solve ends when no step decreases the merit, even after the recoveries."""
        violation, optimality = state.point.violation, state.optimality
        if optimality <= max(100 * self.tolerance, _STALL_GRADIENT) and violation <= self.constraint_tolerance:
            return Stop(Status.SOLVED_ACCEPTABLE, "no step decreases the objective any further")
        status = Status.CONSTRAINTS_VIOLATED if violation > self.constraint_tolerance else Status.FAILED
        return Stop(status, f"no step decreases the merit any further (violation {violation:.3g}, gradient {optimality:.3g})")

    def _penalty(self, point: Iterate) -> float:
        """The merit's l1 violation, counted from half the tolerance: violations the solution may keep cost
        nothing, so the curvature of many nearly active limits cannot block steps that lower f."""
        if point.largest <= 0.5 * self.constraint_tolerance:
            return 0.0
        return float(np.maximum(point.c - 0.5 * self.constraint_tolerance, 0.0).sum())

    def _line_search(self, point: Iterate, step: np.ndarray, working: np.ndarray, correct,
                     merit_weight: float, full_step_likely: bool, gradient: bool = True) -> Backtracked[Iterate]:
        """alpha and the accepted point alpha·``step`` away by Armijo's rule on the l1 merit, with second-order
        corrections; alpha 0 and no point when no step length is accepted.

        Trials are evaluated value-only (``value``) and the accepted one then with its gradient, except the full
        step when ``full_step_likely`` (the last line search took its full step) and no constraint is in the
        working set: that trial is evaluated with its gradient at once, saving the value-only call on most iterations
        for a wasted gradient on the few whose full step fails. Without ``gradient`` every trial is value-only and
        the accepted point keeps no gradient."""
        penalty = self._penalty(point)
        merit = point.f + merit_weight * penalty
        slope = point.g @ step - merit_weight * penalty  # directional derivative of the merit
        if not slope < -1e-16 * max(1.0, abs(merit)):
            return _NO_STEP

        def attempt(alpha: float, bound: float) -> Iterate | None:
            trial = self._trial(point.x + step if alpha == 1.0 else point.x + alpha * step,
                                with_gradient=gradient and full_step_likely and alpha == 1.0 and not len(working))
            if trial is None:
                return None
            if len(working) and self._penalty(trial) > penalty:
                # second-order correction: the step broke the curved constraints; pull it back onto their
                # linearisation at the trial point (Nocedal & Wright 2006, sec. 18.3). Tried at every
                # backtrack: along a limit the iterate follows for many steps, the shorter steps break it too.
                corrected = self._trial(trial.x + correct(trial.c[working]))
                if corrected is not None and corrected.f + merit_weight * self._penalty(corrected) <= bound:
                    trial = corrected
            if trial.f + merit_weight * self._penalty(trial) > bound:
                return None
            if trial.g is None and gradient:  # a trial evaluated with its gradient was checked finite by _trial
                return self.finite_point(trial.x, self.evaluate(trial.x))
            return trial

        searched = backtrack(attempt, merit, slope, max_trials=_BACKTRACKS)
        return searched if searched.accepted is not None else _NO_STEP

    def _trial(self, x: np.ndarray, with_gradient: bool = False) -> Iterate | None:
        """The point x evaluated (value only when a cheaper ``value`` is given, unless ``with_gradient``); None where
        not finite."""
        evaluate = self.evaluate if self.value is None or with_gradient else self.value
        return self.finite_point(x, evaluate(x))

    def _restore(self, point: Iterate, gradient: bool = True) -> Iterate | None:
        """A feasibility step when the merit cannot decrease: the least-norm move d with A_V d = -c_V over
        the violated rows V, halved until the largest violation shrinks; None if it does not. Trials are evaluated
        value-only (the violation needs no gradient), the accepted one then with its gradient unless not
        ``gradient``."""
        step = restoration_step(point)

        def attempt(alpha: float, bound: float) -> Iterate | None:
            # the violation must halve: the merit's bound does not apply
            trial = self._trial(point.x + alpha * step)
            if trial is None or not trial.violation < 0.5 * point.violation:
                return None
            if trial.g is None and gradient:
                return self.finite_point(trial.x, self.evaluate(trial.x))
            return trial

        return backtrack(attempt, point.violation, 0.0, max_trials=_RESTORATION_TRIALS).accepted
