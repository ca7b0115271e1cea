"""A regularised Newton method for smooth problems with inequality constraints (active-set SQP):

    min f(x)  subject to  lb ≤ x ≤ ub  and  c(x) ≤ 0.

The planner's problem has a few hundred unknowns, a dense Hessian that is cheap to assemble from per-step
pieces (:mod:`comanip.planning.curvature`), and constraints (torque bounds, joint limits on the mean path)
that bind at a handful of steps at most. A general NLP solver spends more per iteration on its own
machinery than the Hessian costs (IPOPT with MUMPS: about 1 ms per iteration for 150 unknowns), so the
iteration is written out here:

- Working set W: the constraints within ``margin`` of binding (c_j > -margin), bounds included as rows of
  ±I. Without any, the step is the Newton step.
- Direction: minimise the quadratic model gᵀp + ½ pᵀ(H + delta·s·I)p subject to the linearised working
  constraints c_W + A_W p = 0, by one Cholesky factorisation and a Schur complement on the few rows of W;
  a constraint that is not violated beyond ``constraint_tolerance`` and gets a negative multiplier leaves W
  and the step is recomputed. s = max |diag H|; delta is 0 whenever H is positive definite, otherwise the
  smallest of delta_last/3, 8·delta_last/3, ... (1e-4 the first time) for which the factorisation succeeds
  (IPOPT's inertia correction).
- Step: backtracking, alpha = 1, 1/2, ..., on the l1 merit f + mu Σ max(0, c - constraint_tolerance/2)
  (mu ≥ 2 max multiplier) until it decreases by 1e-4 of its directional derivative (Armijo); a trial that
  raises the violation gets a second-order correction first.
- Secant correction (``secant=True``, for approximate Hessians): C is updated after every step s with
  the symmetric rank-one formula C += r rᵀ / (rᵀ s), r = y - (H + C) s, y the change of gradient, and
  H + C is used in place of H. It learns the curvature the approximation misses along the directions
  the iteration actually moves in (on the Panda: five times fewer iterations, benchmarks/README.md).
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

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.linalg

_ARMIJO = 1e-4
"""Fraction of the linearly predicted decrease a step must achieve."""
_BACKTRACKS = 30
_RECOVERIES, _RECOVERY_SHIFT = 3, 1e-3
"""Attempts after a failed line search, and the least relative shift delta of the first (ten times more each after)."""
_STALL_WINDOW, _STALL_DECREASE, _STALL_GRADIENT = 5, 1e-8, 1e-4
"""Iterations, relative decrease of f over them, and gradient for the stagnation test."""


@dataclass
class NewtonResult:
    """Outcome of :func:`newton_minimize`."""

    x: np.ndarray
    """Best point found (N,)."""
    f: float
    status: str
    """'solved', 'solved_acceptable', 'max_iterations', 'max_wall_time', 'constraints_violated' or 'failed'."""
    message: str
    iterations: int
    """Hessian evaluations (one per accepted step)."""
    projected_gradient: float
    """max |∇f + A_Wᵀ lambda| (the Lagrangian's gradient over the working set) at x."""
    violation: float = 0.0
    """Largest constraint violation max(0, c) at x, bounds included."""


def newton_minimize(evaluate: Callable[[np.ndarray], tuple[float, np.ndarray, Any]],
                    hessian: Callable[[Any], np.ndarray], x0: np.ndarray, lb: np.ndarray, ub: np.ndarray, *,
                    tolerance: float, max_iterations: int, secant: bool = False,
                    constraints: Callable[[np.ndarray, Any], tuple[np.ndarray, Callable]] | None = None,
                    constraint_tolerance: float = 1e-6, margin: float = 1e-3,
                    expired: Callable[[], bool] = lambda: False,
                    value: Callable[[np.ndarray], tuple[float, Any]] | None = None) -> NewtonResult:
    """Minimise f over the box [lb, ub] and c(x) ≤ 0 from x0.

    Args:
        evaluate: x (N,) -> (f, grad f (N,), data); ``data`` is handed to ``hessian`` and ``constraints``.
        hessian: data -> ∇²f (N, N), symmetric.
        x0: start (N,), projected onto the box; lb, ub: bounds (N,), ±inf allowed.
        tolerance: on max |gradient of the Lagrangian|.
        max_iterations: Hessian evaluations allowed.
        secant: add symmetric rank-one corrections to an approximate Hessian.
        constraints: (x, data) -> (c (m,), rows), rows(indices) -> dc_indices/dx (len(indices), N); None
            for none. Entries of c may be -inf (no constraint).
        constraint_tolerance: largest violation a solution may keep (units of c).
        margin: constraints with c > -margin are in the working set.
        expired: called between evaluations; True stops with status 'max_wall_time'.
        value: x -> (f, data) without the gradient, for line-search trials when that is much cheaper than
            ``evaluate`` (``data`` then only needs what ``constraints`` reads); ``evaluate`` runs once a trial
            is accepted. None: trials use ``evaluate``.
    """
    def probe(point):
        """(f, gradient or None, data) at a trial point."""
        if value is None:
            return evaluate(point)
        f_point, data_point = value(point)
        return f_point, None, data_point

    def penalty(c_point) -> float:
        """The merit's l1 violation, counted from half the tolerance: violations the solution may keep cost
        nothing, so the curvature of many nearly active limits cannot block steps that lower f."""
        return float(np.sum(np.maximum(c_point - 0.5 * constraint_tolerance, 0.0)))

    def finite(f_point, g_point) -> bool:
        return bool(np.isfinite(f_point)) and (g_point is None or bool(np.all(np.isfinite(g_point))))

    problem = _Constraints(lb, ub, constraints)
    x = np.clip(np.asarray(x0, dtype=float), lb, ub)
    f, g, data = evaluate(x)
    if not (np.isfinite(f) and np.all(np.isfinite(g))):
        return NewtonResult(x, f, "failed", "objective or gradient not finite at the start", 0, np.inf)
    c, A = problem(x, data)
    delta_last, mu, iterations = 0.0, 0.0, 0
    correction, previous = None, None  # secant correction; (x, g) before the last step
    recoveries = 0  # consecutive iterations whose step was recomputed after a failed line search
    history = [f]

    def result(status, message, gradient):
        return NewtonResult(x, f, status, message, iterations, gradient, problem.violation(c))

    while True:
        if iterations >= max_iterations:
            return result("max_iterations", f"{iterations} iterations", np.inf)
        if expired():
            return result("max_wall_time", "wall-time budget spent", np.inf)
        H = hessian(data)
        iterations += 1
        if not np.all(np.isfinite(H)):
            return result("failed", "Hessian not finite", np.inf)
        if secant:
            correction = np.zeros_like(H) if correction is None else correction
            if previous is not None:
                _symmetric_rank_one_update(correction, H, x - previous[0], g - previous[1])
            H = H + correction
            previous = (x, g)
        # after a failed line search, a stronger shift turns the step towards steepest descent
        least = _RECOVERY_SHIFT * 10.0 ** (recoveries - 1) if recoveries else 0.0
        factor, delta_last = _regularised_cholesky(H, delta_last, least)
        if factor is None:
            return result("failed", "no positive definite regularised Hessian", np.inf)
        step, multipliers, working, correct = _constrained_step(factor, g, c, A, margin, constraint_tolerance)
        lagrangian_gradient = float(np.max(np.abs(g + A(working).T @ multipliers)))
        violation = problem.violation(c)
        if lagrangian_gradient <= tolerance and violation <= constraint_tolerance:
            return result("solved", "gradient of the Lagrangian below tolerance", lagrangian_gradient)
        if len(history) > _STALL_WINDOW and lagrangian_gradient <= _STALL_GRADIENT and violation <= constraint_tolerance \
                and history[-1 - _STALL_WINDOW] - f <= _STALL_DECREASE * abs(f):
            return result("solved_acceptable", f"objective unchanged to {_STALL_DECREASE:g} over {_STALL_WINDOW} "
                          "iterations", lagrangian_gradient)
        mu = max(mu, 2 * float(np.max(multipliers, initial=0.0)))
        merit = f + mu * penalty(c)
        slope = g @ step - mu * penalty(c)  # directional derivative of the merit
        alpha, accepted = 1.0, False
        for attempt in range(_BACKTRACKS):
            if not slope < -1e-16 * max(1.0, abs(merit)):
                break
            trial = x + alpha * step
            f_trial, g_trial, data_trial = probe(trial)
            if finite(f_trial, g_trial):
                c_trial, A_trial = problem(trial, data_trial)
                if len(working) and penalty(c_trial) > penalty(c):
                    # second-order correction: the step broke the curved constraints; pull it back onto their
                    # linearisation at the trial point (Nocedal & Wright 2006, sec. 18.3). Tried at every
                    # backtrack: along a limit the arm follows for many steps, the shorter steps break it too.
                    corrected = trial + correct(c_trial[working])
                    f_corr, g_corr, data_corr = probe(corrected)
                    if finite(f_corr, g_corr):
                        c_corr, A_corr = problem(corrected, data_corr)
                        if f_corr + mu * penalty(c_corr) <= merit + _ARMIJO * alpha * slope:
                            trial, f_trial, g_trial, data_trial, c_trial, A_trial = corrected, f_corr, g_corr, data_corr, c_corr, A_corr
                if f_trial + mu * penalty(c_trial) <= merit + _ARMIJO * alpha * slope:
                    if g_trial is None:
                        f_trial, g_trial, data_trial = evaluate(trial)
                        c_trial, A_trial = problem(trial, data_trial)
                    if finite(f_trial, g_trial):
                        x, f, g, data, c, A = trial, f_trial, g_trial, data_trial, c_trial, A_trial
                        history.append(f)
                        accepted = True
                        break
            alpha /= 2
        if accepted:
            recoveries = 0
            continue
        if problem.violation(c) > constraint_tolerance:
            restored = _restore(evaluate, problem, x, c, A)
            if restored is not None:
                x, f, g, data, c, A = restored
                history.append(f)
                continue
        if recoveries < _RECOVERIES:
            # The quadratic model was wrong along this step: forget the secant corrections (they may have
            # learnt curvature from far away) and regularise harder, then try again from the same point.
            recoveries += 1
            correction, previous = None, None
            continue
        violation = problem.violation(c)
        if lagrangian_gradient <= max(100 * tolerance, _STALL_GRADIENT) and violation <= constraint_tolerance:
            return result("solved_acceptable", "no step decreases the objective any further", lagrangian_gradient)
        status = "constraints_violated" if violation > constraint_tolerance else "failed"
        return result(status, f"no step decreases the merit any further (violation {violation:.3g}, gradient "
                      f"{lagrangian_gradient:.3g})", lagrangian_gradient)


def _restore(evaluate, problem, x, c, A):
    """A feasibility step when the merit cannot decrease: the least-norm move d with A_V d = -c_V over the
    violated rows V, halved until the largest violation shrinks; None if it does not."""
    violated = np.flatnonzero(c > 0)
    rows = A(violated)
    step = -rows.T @ np.linalg.lstsq(rows @ rows.T, c[violated], rcond=None)[0]
    for alpha in (1.0, 0.5, 0.25, 0.125):
        trial = x + alpha * step
        f, g, data = evaluate(trial)
        if np.isfinite(f) and np.all(np.isfinite(g)):
            c_trial, A_trial = problem(trial, data)
            if problem.violation(c_trial) < 0.5 * problem.violation(c):
                return trial, f, g, data, c_trial, A_trial
    return None


class _Constraints:
    """c(x) ≤ 0 and rows of its Jacobian on demand: the finite bounds (rows of ±I), then the user's."""

    def __init__(self, lb, ub, constraints):
        self.constraints = constraints
        self.upper = np.flatnonzero(np.isfinite(ub))
        self.lower = np.flatnonzero(np.isfinite(lb))
        self.lb, self.ub, self.size = lb, ub, len(lb)

    def __call__(self, x, data):
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

    @staticmethod
    def violation(c) -> float:
        return float(max(0.0, np.max(c, initial=0.0)))


def _constrained_step(factor, g, c, A, margin: float, tolerance: float):
    """Newton step under the working set's linearised constraints.

    A(indices) gives the constraints' Jacobian rows. Working rows: c_j > -margin; a row with a negative
    multiplier is dropped and the step recomputed unless it is violated by more than ``tolerance`` (then
    the step must restore it). (Keeping a row met to within the tolerance, say at 3e-8 past a joint limit,
    held the Panda's plans on the limit while the objective pulled them off it: the step vanished and
    the solve stalled with a large Lagrangian gradient.) Returns (step,
    multipliers, working rows, correct), correct(c_W) the least-H-norm move d with A_W d = -c_W.
    """
    Hg = scipy.linalg.cho_solve(factor, g, check_finite=False)
    working = np.flatnonzero(c > -margin)
    while len(working):
        rows = A(working)
        HA = scipy.linalg.cho_solve(factor, rows.T, check_finite=False)
        schur = rows @ HA
        multipliers = np.linalg.lstsq(schur, c[working] - rows @ Hg, rcond=None)[0]
        dropping = (multipliers < 0) & (c[working] <= tolerance)
        if not dropping.any():
            multipliers = np.maximum(multipliers, 0.0)

            def correct(c_working, HA=HA, schur=schur):
                return -HA @ np.linalg.lstsq(schur, c_working, rcond=None)[0]

            return -(Hg + HA @ multipliers), multipliers, working, correct
        working = working[~dropping]
    return -Hg, np.zeros(0), working, None


def _symmetric_rank_one_update(correction: np.ndarray, H: np.ndarray, s: np.ndarray, y: np.ndarray) -> None:
    """correction += r rᵀ / (rᵀ s), r = y - (H + correction) s, in place; skipped when rᵀ s is tiny
    (the usual safeguard: |rᵀ s| ≥ 1e-8 |r| |s|)."""
    r = y - (H + correction) @ s
    denominator = r @ s
    if abs(denominator) > 1e-8 * np.linalg.norm(r) * np.linalg.norm(s):
        correction += np.outer(r, r) / denominator


def _regularised_cholesky(H: np.ndarray, delta_last: float, least: float = 0.0):
    """Cholesky factor of H + delta·s·I with the least delta ≥ ``least`` tried that works; returns
    (factor, delta_last).

    delta = 0 first (unless ``least`` > 0); then delta_last/3 (or 1e-4 if no regularisation was needed
    before), growing by 8 (by 100 the first time), as IPOPT does. s = max |diag H| makes delta relative.
    """
    if least == 0.0:
        try:
            return scipy.linalg.cho_factor(H, check_finite=False), delta_last
        except scipy.linalg.LinAlgError:
            pass
    diagonal = np.diag(H)
    scale = max(float(np.max(np.abs(diagonal))), np.finfo(float).tiny)
    shifted = H.copy()
    delta = max(least, 1e-4 if delta_last == 0 else max(delta_last / 3, 1e-20))
    growth = 100.0 if delta_last == 0 else 8.0
    while delta < 1e20:
        np.fill_diagonal(shifted, diagonal + delta * scale)
        try:
            return scipy.linalg.cho_factor(shifted, check_finite=False), delta
        except scipy.linalg.LinAlgError:
            delta *= growth
    return None, delta_last
