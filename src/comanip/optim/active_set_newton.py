"""A regularised Newton method for smooth problems with inequality constraints (active-set SQP):

    min f(x)  subject to  lb ≤ x ≤ ub  and  c(x) ≤ 0.

The planner's problem has a few hundred unknowns, a dense Hessian that is cheap to assemble from per-step
pieces (:mod:`comanip.planning.curvature`), and constraints (torque bounds, joint limits on the mean path)
that bind at a handful of steps at most. A general NLP solver spends more per iteration on its own
machinery than the Hessian costs (IPOPT with MUMPS: about 1 ms per iteration for 150 unknowns), so the
iteration is written out here:

Solver quantities are named as in ``docs/notation.md``: ``hessian`` (∇²f, not the horizon H), the
``working`` set of constraint rows (not the goal covariance W), ``merit_weight`` (not the mean mu) and
``multipliers`` (not the effort weight nu). The factorisation, line search, status and result are those
of :mod:`comanip.optim`.

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
  the iteration actually moves in (on the Panda: five times fewer iterations, benchmarks/README.md).
- Chord steps (exact Hessians, ``secant=False``): while no constraint is in the working set and the last step
  cut max |∇f| at least tenfold, the next step reuses that step's factorisation instead of evaluating and
  factoring a new Hessian (Kelley 2003, sec. 5.4: the chord method); a step that cuts it less, or fails the
  line search, brings a fresh Hessian back. On warm point-mass solves it saves one Hessian and factorisation
  of about four, for one more cheap iteration (benchmarks/README.md); the optimum is the same (J to ~1e-11).
- Lazy assembly (approximate Hessians, ``hessian_refresh`` k > 1): the hessian is assembled only every k-th
  iteration, and whenever the last step was shortened by the line search or taken with constraints in the
  working set (there the model had been wrong, or the iterate follows a limit: on the Panda's reaches along a
  joint limit keeping the hessian then ended 1e-4 to 6e-3 worse); in between the last one is kept and the
  secant corrections, updated against it, carry the change of curvature (an update costs about a twentieth of
  an assembly on the Panda). The Cholesky factor of the last factored matrix then takes those rank-one updates
  by the Woodbury identity, when it needed no shift and stays positive definite (checked by the inertia of the small
  capacitance matrix), instead of a new factorisation. The gradient is evaluated at every iterate, so the
  convergence test and the optimum are those of k = 1.
- Restoration: when no step decreases the merit while a constraint is violated, the least-norm step onto
  the violated constraints' linearisation is taken if it halves the violation.
- Recovery: when no step decreases the merit otherwise, the secant corrections are dropped and the step is
  recomputed with delta ≥ 1e-3, then 1e-2, 1e-1 (turning it towards steepest descent), before giving up.
  With the working-set and merit rules above it took failed closed-loop Panda replans from 11 in 40 to 1.
- Convergence: max |∇f + A_Wᵀ lambda| ≤ tolerance with every constraint violated by at most
  ``constraint_tolerance`` ('solved'). If the merit cannot be decreased any more in floating point, the
  point is 'solved_acceptable' when the constraints are met and that gradient is below 1e-4 (or 100 ×
  tolerance, if larger). It is 'solved_acceptable' too when f has decreased by less than 1e-8 |f| over the
  last five iterations with the gradient below 1e-4 and the constraints met: along the nearly flat
  directions of a redundant arm an approximate Hessian converges linearly and slowly, while the plan
  stopped changing long before.

f must be finite at x0; a trial point where f is not finite is treated as a failed trial.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from comanip.arguments import as_count
from comanip.optim import SolverResult, Status, backtrack, cholesky_solve, growing_shifts, shifted_cholesky

_BACKTRACKS = 30
"""Step lengths tried by one line search."""
_RECOVERIES, _RECOVERY_SHIFT = 3, 1e-3
"""Attempts after a failed line search, and the least relative shift delta of the first (ten times more each after)."""
_STALL_WINDOW, _STALL_DECREASE, _STALL_GRADIENT = 5, 1e-8, 1e-4
"""Iterations, relative decrease of f over them, and gradient for the stagnation test."""
_REUSE_RATIO = 0.1
"""An exact Hessian's factor is reused while each step cuts the gradient by at least this factor."""
_NO_ROWS, _NO_MULTIPLIERS = np.zeros(0, dtype=int), np.zeros(0)
"""An empty working set and its multipliers (read only)."""


def newton_minimize(evaluate: Callable[[np.ndarray], tuple[float, np.ndarray, Any]],
                    hessian: Callable[[Any], np.ndarray], x0: np.ndarray, lb: np.ndarray, ub: np.ndarray, *,
                    tolerance: float, max_iterations: int, secant: bool = False,
                    constraints: Callable[[np.ndarray, Any], tuple[np.ndarray, Callable]] | None = None,
                    constraint_tolerance: float = 1e-6, margin: float = 1e-3,
                    expired: Callable[[], bool] = lambda: False,
                    value: Callable[[np.ndarray], tuple[float, Any]] | None = None,
                    hessian_refresh: int = 1) -> SolverResult[np.ndarray]:
    """Minimise f over the box [lb, ub] and c(x) ≤ 0 from x0.

    Args:
        evaluate: x (N,) -> (f, grad f (N,), data); ``data`` is handed to ``hessian`` and ``constraints``.
        hessian: data -> ∇²f (N, N), symmetric (the solver does not modify it).
        x0: start (N,), projected onto the box; lb, ub: bounds (N,), ±inf allowed.
        tolerance: on max |gradient of the Lagrangian|.
        max_iterations: iterations allowed (each evaluates the Hessian, except a last one that only finds the
            point converged).
        secant: add symmetric rank-one corrections to an approximate Hessian.
        constraints: (x, data) -> (c (m,), rows), rows(indices) -> dc_indices/dx (len(indices), N); None
            for none. Entries of c may be -inf (no constraint).
        constraint_tolerance: largest violation a solution may keep (units of c).
        margin: constraints with c > -margin are in the working set.
        expired: called between evaluations; True stops with status 'max_wall_time'.
        value: x -> (f, data) without the gradient, for line-search trials when that is much cheaper than
            ``evaluate`` (``data`` then only needs what ``constraints`` reads); ``evaluate`` runs once a trial
            is accepted. None: trials use ``evaluate``.
        hessian_refresh: with ``secant``, assemble ``hessian`` every this many iterations (and after any step that
            was not a full, unconstrained one), keeping the last one with updated secant corrections in between; 1:
            every iteration. Must be 1 without ``secant`` (an exact Hessian is assembled at every iteration, chord
            steps apart).

    Returns:
        A :class:`~comanip.optim.SolverResult`: x the best point (N,), fun its f, nit the iterations,
        optimality max |∇f + A_Wᵀ multipliers| there, violation max(0, c) bounds included, local_model
        (factor, data): the Cholesky factor of the (regularised, corrected) Hessian of the last step taken (None if
        no step was taken or its matrix had secant updates since it was factored) and the evaluation's ``data``
        at x.
    """
    if type(hessian_refresh) is not int or hessian_refresh != 1:
        hessian_refresh = as_count("hessian_refresh", hessian_refresh, unit="iterations")
    if hessian_refresh > 1 and not secant:
        raise ValueError(f"hessian_refresh must be 1 without secant corrections (an exact Hessian is assembled at "
                         f"every iteration), got {hessian_refresh}")
    solver = _ActiveSetNewton(evaluate, hessian, _Constraints(lb, ub, constraints), value, tolerance=tolerance,
                              constraint_tolerance=constraint_tolerance, margin=margin, hessian_refresh=hessian_refresh)
    problem = solver.problem
    x = np.array(x0, dtype=float) if problem.unbounded else np.clip(np.asarray(x0, dtype=float), lb, ub)
    f, g, data = evaluate(x)
    if not _finite(f, g):
        return SolverResult(x, f, Status.FAILED, "objective or gradient not finite at the start", 0, np.inf)
    return solver.run(solver.at(x, f, g, data), max_iterations, secant, expired)


@dataclass(slots=True)
class _Iterate:
    """A point x (N,) and what was evaluated there: f, its gradient (None after a value-only trial), the
    evaluation's data, the constraints c (bounds first) and rows(indices) of their Jacobian."""

    x: np.ndarray
    f: float
    g: np.ndarray | None
    data: Any
    c: np.ndarray
    rows: Callable[[np.ndarray], np.ndarray]
    largest: float = field(init=False)
    """max c (-inf without constraints): the working set, the violation and the merit's penalty read it first."""

    def __post_init__(self):
        self.largest = float(self.c.max()) if len(self.c) else -math.inf

    @property
    def violation(self) -> float:
        """max(0, c): the largest violation, bounds included."""
        return max(0.0, self.largest)


@dataclass
class _ActiveSetNewton:
    """The method of the module docstring for one problem; :meth:`run` iterates from a point."""

    evaluate: Callable
    hessian: Callable
    problem: "_Constraints"
    value: Callable | None
    tolerance: float
    constraint_tolerance: float
    margin: float
    hessian_refresh: int = 1

    def at(self, x, f, g, data) -> _Iterate:
        return _Iterate(x, f, g, data, *self.problem(x, data))

    def run(self, point: _Iterate, max_iterations: int, secant: bool, expired) -> SolverResult[np.ndarray]:
        shift_last, merit_weight, iterations = 0.0, 0.0, 0
        correction, previous = None, None  # secant correction; (x, g) before the last step
        assembled, age = None, 0  # with secant: the last assembled hessian, and the iterations it has served
        model_held = False  # the last step was a full step with no constraint in the working set
        full_steps = True  # the last line search took the full step: evaluate the next full step with its gradient
        updated = None  # with secant: the last factored matrix's _UpdatedFactor
        recoveries = 0  # consecutive iterations whose step was recomputed after a failed line search
        history = [point.f]
        kept = None  # an exact Hessian's factor and the optimality where the last step was taken (Chord steps)
        stepped_with = None  # the factorisation of the last step taken

        def result(status, message, optimality):
            return SolverResult(point.x, point.f, status, message, iterations, optimality, point.violation,
                                (stepped_with, point.data))

        while True:
            if iterations >= max_iterations:
                return result(Status.MAX_ITERATIONS, f"{iterations} iterations", np.inf)
            if expired():
                return result(Status.MAX_WALL_TIME, "wall-time budget spent", np.inf)
            iterations += 1
            free = point.largest <= -self.margin
            if free:
                # no constraint in the working set: the Lagrangian's gradient is the gradient, and a converged
                # point needs no Hessian (a warm point-mass solve's last of about five)
                optimality = float(np.abs(point.g).max())
                converged = self._converged(optimality, point, history)
                if converged is not None:
                    return result(*converged, optimality)
                if not secant and recoveries == 0 and kept is not None and optimality <= _REUSE_RATIO * kept[1]:
                    # the last step cut the gradient tenfold: the factor it used still models the curvature
                    # well enough (a chord step, Kelley 2003, sec. 5.4), at a third of a point mass's iteration
                    step = -cholesky_solve(kept[0], point.g)
                    kept = (kept[0], optimality)
                    alpha, accepted = self._line_search(point, step, _NO_ROWS, None, merit_weight, full_steps)
                    full_steps = alpha == 1.0
                    if accepted is not None:
                        point, stepped_with = accepted, kept[0]
                        history.append(point.f)
                        continue
            kept = None
            if not secant:
                hessian = self.hessian(point.data)
                if not np.isfinite(hessian).all():
                    return result(Status.FAILED, "Hessian not finite", np.inf)
            else:
                reused = assembled is not None and age < self.hessian_refresh and model_held
                if not reused:
                    assembled, age = self.hessian(point.data), 0
                    if not np.isfinite(assembled).all():
                        return result(Status.FAILED, "Hessian not finite", np.inf)
                age += 1
                correction = np.zeros_like(assembled) if correction is None else correction
                update = None
                if previous is not None:
                    update = _symmetric_rank_one_update(correction, assembled, point.x - previous[0], point.g - previous[1])
                previous = (point.x, point.g)
                # between assemblies the last factor takes the secant updates (Woodbury), unless it was shifted or
                # an update leaves the matrix indefinite: then the matrix is factored anew, with the shifts below
                updated = updated.updated(update) if reused and not recoveries and updated.shift == 0 else None
                hessian = None if updated is not None else assembled + correction
            if hessian is not None:
                # after a failed line search, a stronger shift turns the step towards steepest descent
                least = _RECOVERY_SHIFT * 10.0 ** (recoveries - 1) if recoveries else 0.0
                factor, shift = shifted_cholesky(hessian, growing_shifts(shift_last, least))
                if factor is None:
                    return result(Status.FAILED, "no positive definite regularised Hessian", np.inf)
                shift_last = shift if shift > 0 else shift_last
                if secant:
                    updated = _UpdatedFactor(factor, shift)
            if secant:
                factor, solve = updated.factor, updated.solve
            else:
                solve = lambda b, factor=factor: cholesky_solve(factor, b)  # noqa: E731
            if free:  # the Newton step; its optimality was tested above
                step, multipliers, working, correct = -solve(point.g), _NO_MULTIPLIERS, _NO_ROWS, None
            else:
                step, multipliers, working, correct = _constrained_step(solve, point.g, point.c, point.rows, self.margin,
                                                                        self.constraint_tolerance)
                lagrangian_gradient = point.g + point.rows(working).T @ multipliers if len(working) else point.g
                optimality = float(np.abs(lagrangian_gradient).max())
                converged = self._converged(optimality, point, history)
                if converged is not None:
                    return result(*converged, optimality)
            if free and not secant:
                kept = (factor, optimality)
            if len(multipliers):
                merit_weight = max(merit_weight, 2 * float(np.max(multipliers)))
            alpha, accepted = self._line_search(point, step, working, correct, merit_weight, full_steps)
            model_held = alpha == 1.0 and len(working) == 0
            full_steps = alpha == 1.0
            if accepted is None and point.violation > self.constraint_tolerance:
                accepted = self._restore(point)
            elif accepted is not None:
                recoveries = 0
            if accepted is not None:
                point, stepped_with = accepted, factor
                history.append(point.f)
                continue
            if recoveries < _RECOVERIES:
                # The quadratic model was wrong along this step: forget the secant corrections (they may have
                # learnt curvature from far away) and regularise harder, then try again from the same point.
                recoveries += 1
                correction, previous, assembled = None, None, None
                continue
            return result(*self._final_status(optimality, point), optimality)

    def _converged(self, optimality: float, point: _Iterate, history: list[float]) -> tuple[Status, str] | None:
        """(status, message) when the point is a solution (module docstring, Convergence), else None."""
        violation = point.violation
        if violation > self.constraint_tolerance:
            return None
        if optimality <= self.tolerance:
            return Status.SOLVED, "gradient of the Lagrangian below tolerance"
        if len(history) > _STALL_WINDOW and optimality <= _STALL_GRADIENT \
                and history[-1 - _STALL_WINDOW] - point.f <= _STALL_DECREASE * abs(point.f):
            return Status.SOLVED_ACCEPTABLE, f"objective unchanged to {_STALL_DECREASE:g} over {_STALL_WINDOW} iterations"
        return None

    def _final_status(self, optimality: float, point: _Iterate) -> tuple[Status, str]:
        """(status, message) when no step decreases the merit, even after the recoveries."""
        violation = point.violation
        if optimality <= max(100 * self.tolerance, _STALL_GRADIENT) and violation <= self.constraint_tolerance:
            return Status.SOLVED_ACCEPTABLE, "no step decreases the objective any further"
        status = Status.CONSTRAINTS_VIOLATED if violation > self.constraint_tolerance else Status.FAILED
        return status, f"no step decreases the merit any further (violation {violation:.3g}, gradient {optimality:.3g})"

    def _penalty(self, point: _Iterate) -> float:
        """The merit's l1 violation, counted from half the tolerance: violations the solution may keep cost
        nothing, so the curvature of many nearly active limits cannot block steps that lower f."""
        if point.largest <= 0.5 * self.constraint_tolerance:
            return 0.0
        return float(np.maximum(point.c - 0.5 * self.constraint_tolerance, 0.0).sum())

    def _line_search(self, point: _Iterate, step: np.ndarray, working: np.ndarray, correct,
                     merit_weight: float, full_step_likely: bool) -> tuple[float, _Iterate | None]:
        """(alpha, the accepted point alpha·``step`` away) by Armijo's rule on the l1 merit, with second-order
        corrections; (0, None) when no step length is accepted.

        Trials are evaluated value-only (``value``) and the accepted one then with its gradient, except the full
        step when ``full_step_likely`` (the last line search took its full step) and no constraint is in the
        working set: that trial is evaluated with its gradient at once, saving the value-only call (a fifth of
        an evaluation on the Panda) on most iterations for a wasted gradient on the few whose full step fails."""
        penalty = self._penalty(point)
        merit = point.f + merit_weight * penalty
        slope = point.g @ step - merit_weight * penalty  # directional derivative of the merit
        if not slope < -1e-16 * max(1.0, abs(merit)):
            return 0.0, None

        def attempt(alpha: float, bound: float) -> _Iterate | None:
            trial = self._trial(point.x + step if alpha == 1.0 else point.x + alpha * step,
                                with_gradient=full_step_likely and alpha == 1.0 and not len(working))
            if trial is None:
                return None
            if len(working) and self._penalty(trial) > penalty:
                # second-order correction: the step broke the curved constraints; pull it back onto their
                # linearisation at the trial point (Nocedal & Wright 2006, sec. 18.3). Tried at every
                # backtrack: along a limit the arm follows for many steps, the shorter steps break it too.
                corrected = self._trial(trial.x + correct(trial.c[working]))
                if corrected is not None and corrected.f + merit_weight * self._penalty(corrected) <= bound:
                    trial = corrected
            if trial.f + merit_weight * self._penalty(trial) > bound:
                return None
            if trial.g is None:  # a trial evaluated with its gradient was checked finite by _trial
                trial = self.at(trial.x, *self.evaluate(trial.x))
                return trial if _finite(trial.f, trial.g) else None
            return trial

        alpha, accepted = backtrack(attempt, merit, slope, max_trials=_BACKTRACKS)
        return (alpha, accepted) if accepted is not None else (0.0, None)

    def _trial(self, x: np.ndarray, with_gradient: bool = False) -> _Iterate | None:
        """The point x evaluated (value only when a cheaper ``value`` is given, unless ``with_gradient``); None where
        not finite."""
        if self.value is None or with_gradient:
            f, g, data = self.evaluate(x)
        else:
            (f, data), g = self.value(x), None
        return self.at(x, f, g, data) if _finite(f, g) else None

    def _restore(self, point: _Iterate) -> _Iterate | None:
        """A feasibility step when the merit cannot decrease: the least-norm move d with A_V d = -c_V over
        the violated rows V, halved until the largest violation shrinks; None if it does not."""
        violated = np.flatnonzero(point.c > 0)
        rows = point.rows(violated)
        step = -rows.T @ np.linalg.lstsq(rows @ rows.T, point.c[violated], rcond=None)[0]
        for alpha in (1.0, 0.5, 0.25, 0.125):
            x = point.x + alpha * step
            f, g, data = self.evaluate(x)
            if np.isfinite(f) and np.all(np.isfinite(g)):
                trial = self.at(x, f, g, data)
                if trial.violation < 0.5 * point.violation:
                    return trial
        return None


def _finite(f: float, g: np.ndarray | None) -> bool:
    """f and every entry of g finite (a sum of finite gradient entries is finite short of overflow, 1e308)."""
    return math.isfinite(f) and (g is None or math.isfinite(g.sum()))


class _Constraints:
    """c(x) ≤ 0 and rows of its Jacobian on demand: the finite bounds (rows of ±I), then the user's."""

    def __init__(self, lb, ub, constraints):
        self.constraints = constraints
        self.upper = np.flatnonzero(np.isfinite(ub))
        self.lower = np.flatnonzero(np.isfinite(lb))
        self.lb, self.ub, self.size = lb, ub, len(lb)
        self.all_finite = len(self.upper) == len(self.lower) == self.size
        self.unbounded = len(self.upper) == len(self.lower) == 0

    def __call__(self, x, data):
        if self.unbounded:  # no finite bound (the point masses' torques): no rows at all
            bounds = _NO_MULTIPLIERS
        elif self.all_finite:  # the usual bounded case (torque bounds): no index arrays to gather through
            bounds = np.concatenate([x - self.ub, self.lb - x])
        else:
            bounds = np.concatenate([x[self.upper] - self.ub[self.upper], self.lb[self.lower] - x[self.lower]])
        if self.constraints is None:
            return bounds, self._bound_rows
        c_user, user_rows = self.constraints(x, data)
        n_bounds = len(bounds)

        def rows(indices):
            out = np.zeros((len(indices), self.size))
            is_bound = indices < n_bounds
            out[is_bound] = self._bound_rows(indices[is_bound])
            if not is_bound.all():
                out[~is_bound] = user_rows(indices[~is_bound] - n_bounds)
            return out

        return np.concatenate([bounds, c_user]), rows

    def _bound_rows(self, indices):
        out = np.zeros((len(indices), self.size))
        n_upper = len(self.upper)
        upper = indices < n_upper
        out[np.flatnonzero(upper), self.upper[indices[upper]]] = 1.0
        out[np.flatnonzero(~upper), self.lower[indices[~upper] - n_upper]] = -1.0
        return out


def _constrained_step(solve, g, c, A, margin: float, tolerance: float):
    """Newton step under the working set's linearised constraints; solve(b) applies the inverse of the regularised
    hessian to b (N,) or (N, k).

    A(indices) gives the constraints' Jacobian rows. Working rows: c_j > -margin; a row with a negative
    multiplier is dropped and the step recomputed unless it is violated by more than ``tolerance`` (then
    the step must restore it), or it is past its limit already and the step without it would move it further
    (then it is kept). (Keeping a row met to within the tolerance, say at 3e-8 past a joint limit,
    held the Panda's plans on the limit while the objective pulled them off it: the step vanished and
    the solve stalled with a large Lagrangian gradient.) Returns (step,
    multipliers, working rows, correct), correct(c_W) the least-H-norm move d with A_W d = -c_W.
    """
    Hg = solve(g)
    near = np.flatnonzero(c > -margin)
    working, pinned = near, np.zeros(0, dtype=int)
    while True:
        if len(working):
            rows = A(working)
            HA = solve(rows.T)
            schur = rows @ HA
            multipliers = np.linalg.lstsq(schur, c[working] - rows @ Hg, rcond=None)[0]
            dropping = (multipliers < 0) & (c[working] <= tolerance) & ~np.isin(working, pinned)
            if dropping.any():
                working = working[~dropping]
                continue
            multipliers = np.maximum(multipliers, 0.0)
            step = -(Hg + HA @ multipliers)
        else:
            multipliers, step = np.zeros(0), -Hg
        # rows dropped together can push one another out: a dropped row already past its limit (within the
        # tolerance) that the step would drive further out returns to the working set for good (on the Panda's
        # reaches along a joint limit such rows made the merit rise at first order along every step, and the
        # solve ended 'failed' at a gradient of 2e-4)
        if len(working) == len(near):
            break
        dropped = np.setdiff1d(near, working, assume_unique=True)
        dropped = dropped[c[dropped] > 0]
        blocking = dropped[A(dropped) @ step > 0] if len(dropped) else dropped
        if not len(blocking):
            break
        pinned = np.union1d(pinned, blocking)
        working = np.union1d(working, blocking)
    if not len(working):
        return step, multipliers, working, None

    def correct(c_working, HA=HA, schur=schur):
        return -HA @ np.linalg.lstsq(schur, c_working, rcond=None)[0]

    return step, multipliers, working, correct


def _symmetric_rank_one_update(correction: np.ndarray, H: np.ndarray, s: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float] | None:
    """correction += r rᵀ / (rᵀ s), r = y - (H + correction) s, in place; skipped when rᵀ s is tiny
    (the usual safeguard: |rᵀ s| ≥ 1e-8 |r| |s|). correction and H (N, N), s and y (N,).

    Returns the update as (u (N,), sign ±1), correction's change being sign·u uᵀ; None when skipped."""
    r = y - H @ s - correction @ s
    denominator = r @ s
    if abs(denominator) > 1e-8 * np.linalg.norm(r) * np.linalg.norm(s):
        u = r / np.sqrt(abs(denominator))  # u_i u_j = u_j u_i: the correction stays exactly symmetric
        sign = float(np.sign(denominator))
        correction += np.outer(u, sign * u)
        return u, sign
    return None


class _UpdatedFactor:
    """Solves with a regularised hessian M = F + U S Uᵀ: F's Cholesky factor (from
    :func:`~comanip.optim.shifted_cholesky`, with its relative ``shift``), and the secant updates made since it was
    factored, U = [u_1 ... u_m] (N, m) with signs S = diag(±1), by the Woodbury identity
    M⁻¹ b = F⁻¹ b - F⁻¹U C⁻¹ Uᵀ F⁻¹ b, C = S⁻¹ + Uᵀ F⁻¹ U (m, m): two triangular solves per update (about
    0.1 ms for the Panda's 350 unknowns) instead of a factorisation (1.1 ms)."""

    def __init__(self, cholesky: tuple, shift: float, vectors: np.ndarray | None = None, signs: np.ndarray | None = None):
        self.cholesky, self.shift = cholesky, shift
        self.vectors = np.zeros((len(cholesky[0]), 0)) if vectors is None else vectors
        self.signs = np.zeros(0) if signs is None else signs
        if len(self.signs):
            self._solved = cholesky_solve(cholesky, self.vectors)  # F⁻¹ U
            self._capacitance = np.diag(self.signs) + self.vectors.T @ self._solved  # S⁻¹ = S for signs ±1

    @property
    def factor(self) -> tuple | None:
        """M's Cholesky factor when no update was made since it was factored (M = F), else None."""
        return None if len(self.signs) else self.cholesky

    def solve(self, b: np.ndarray) -> np.ndarray:
        """M⁻¹ b for b (N,) or (N, k)."""
        x = cholesky_solve(self.cholesky, b)
        if not len(self.signs):
            return x
        return x - self._solved @ np.linalg.solve(self._capacitance, self._solved.T @ b)

    def updated(self, update: tuple[np.ndarray, float] | None) -> "_UpdatedFactor | None":
        """The factor of M + sign·u uᵀ (``update`` as :func:`_symmetric_rank_one_update` returns it; None: M
        itself), or None when that matrix is not safely positive definite. By Haynsworth's inertia additivity
        M + U S Uᵀ is positive definite exactly when C has as many negative eigenvalues as S has negative signs;
        C nearly singular counts as not."""
        if update is None:
            return self
        u, sign = update
        factor = _UpdatedFactor(self.cholesky, self.shift, np.column_stack([self.vectors, u]), np.append(self.signs, sign))
        eigenvalues = np.linalg.eigvalsh(factor._capacitance)
        if np.sum(eigenvalues < 0) != np.sum(factor.signs < 0) or np.min(np.abs(eigenvalues)) <= 1e-8 * np.max(np.abs(eigenvalues)):
            return None
        return factor
