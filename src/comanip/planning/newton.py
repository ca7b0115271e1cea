"""A regularised Newton method for smooth problems with simple bounds: min f(x) subject to lb ≤ x ≤ ub.

The planner's problem has a few hundred unknowns, a dense Hessian that is cheap to assemble from per-step
pieces (:mod:`comanip.planning.curvature`), and no constraints but torque limits. A general NLP solver
spends more per iteration on its own machinery than the Hessian costs (IPOPT with MUMPS: about 1 ms per
iteration for 150 unknowns), so the iteration is written out here, following IPOPT's choices for an
unconstrained problem:

- Direction: p = -(H_FF + delta·s·I)^-1 g_F on the free variables F (those not held at a bound by a
  gradient pushing outwards), s = max |diag H_FF|, by Cholesky. delta is 0 whenever H_FF is positive
  definite; otherwise the smallest of delta_last/3, 8·delta_last/3, ... (1e-4 the first time) for which
  the factorisation succeeds (IPOPT's inertia correction).
- Step: backtracking along the projected path x(alpha) = clip(x + alpha p, lb, ub), alpha = 1, 1/2, ...,
  until the Armijo condition f(x(alpha)) ≤ f(x) + 1e-4 g·(x(alpha) - x) holds.
- Secant correction (``secant=True``, for approximate Hessians): C is updated after every step s with
  the symmetric rank-one formula C += r rᵀ / (rᵀ s), r = y - (H + C) s, y the change of gradient, and
  H + C is used in place of H. It learns the curvature the approximation misses along the directions
  the iteration actually moves in (on the Panda: five times fewer iterations, benchmarks/README.md).
- Convergence: max |projected gradient| ≤ tolerance ('solved'). If no step decreases f any more in
  floating point, the point is 'solved_acceptable' when the projected gradient is within 100 × tolerance.
  It is 'solved_acceptable' too when f has decreased by less than 1e-8 |f| over the last five iterations
  with a projected gradient below 1e-4: along the nearly flat directions of a redundant arm an approximate
  Hessian converges linearly and slowly, while the plan stopped changing long before (Panda:
  |f| resolved to 1e-8 after a third of the iterations a 1e-8 gradient needs).

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
_STALL_WINDOW, _STALL_DECREASE, _STALL_GRADIENT = 5, 1e-8, 1e-4
"""Iterations, relative decrease of f over them, and projected gradient for the stagnation test."""


@dataclass
class NewtonResult:
    """Outcome of :func:`newton_minimize`."""

    x: np.ndarray
    """Best point found (N,)."""
    f: float
    status: str
    """'solved', 'solved_acceptable', 'max_iterations', 'max_wall_time' or 'failed'."""
    message: str
    iterations: int
    """Hessian evaluations (one per accepted step)."""
    projected_gradient: float
    """max |projected gradient| at x."""


def newton_minimize(evaluate: Callable[[np.ndarray], tuple[float, np.ndarray, Any]],
                    hessian: Callable[[Any], np.ndarray], x0: np.ndarray, lb: np.ndarray, ub: np.ndarray, *,
                    tolerance: float, max_iterations: int, secant: bool = False,
                    expired: Callable[[], bool] = lambda: False) -> NewtonResult:
    """Minimise f over the box [lb, ub] from x0.

    Args:
        evaluate: x (N,) -> (f, grad f (N,), data); ``data`` is handed to ``hessian``.
        hessian: data -> ∇²f (N, N), symmetric.
        x0: start (N,), projected onto the box; lb, ub: bounds (N,), ±inf allowed.
        tolerance: on max |projected gradient|.
        max_iterations: Hessian evaluations allowed.
        secant: add symmetric rank-one corrections to an approximate Hessian.
        expired: called between evaluations; True stops with status 'max_wall_time'.
    """
    x = np.clip(np.asarray(x0, dtype=float), lb, ub)
    f, g, data = evaluate(x)
    if not (np.isfinite(f) and np.all(np.isfinite(g))):
        return NewtonResult(x, f, "failed", "objective or gradient not finite at the start", 0, np.inf)
    delta_last = 0.0
    iterations = 0
    correction, previous = None, None  # secant correction; (x, g) before the last step
    history = [f]
    while True:
        free = ~(((x <= lb) & (g > 0)) | ((x >= ub) & (g < 0)))
        projected = float(np.max(np.abs(g[free]), initial=0.0))
        if projected <= tolerance:
            return NewtonResult(x, f, "solved", "projected gradient below tolerance", iterations, projected)
        if len(history) > _STALL_WINDOW and projected <= _STALL_GRADIENT \
                and history[-1 - _STALL_WINDOW] - f <= _STALL_DECREASE * abs(f):
            return NewtonResult(x, f, "solved_acceptable", f"objective unchanged to {_STALL_DECREASE:g} over "
                                f"{_STALL_WINDOW} iterations", iterations, projected)
        if iterations >= max_iterations:
            return NewtonResult(x, f, "max_iterations", f"{iterations} iterations", iterations, projected)
        if expired():
            return NewtonResult(x, f, "max_wall_time", "wall-time budget spent", iterations, projected)
        H = hessian(data)
        iterations += 1
        if not np.all(np.isfinite(H)):
            return NewtonResult(x, f, "failed", "Hessian not finite", iterations, projected)
        if secant:
            correction = np.zeros_like(H) if correction is None else correction
            if previous is not None:
                _symmetric_rank_one_update(correction, H, x - previous[0], g - previous[1])
            H = H + correction
            previous = (x, g)
        H_free = H if free.all() else H[np.ix_(free, free)]
        factor, delta_last = _regularised_cholesky(H_free, delta_last)
        if factor is None:
            return NewtonResult(x, f, "failed", "no positive definite regularised Hessian", iterations, projected)
        step = np.zeros_like(x)
        step[free] = -scipy.linalg.cho_solve(factor, g[free], check_finite=False)
        alpha = 1.0
        for _ in range(_BACKTRACKS):
            trial = np.clip(x + alpha * step, lb, ub)
            decrease = g @ (trial - x)
            if not decrease < -1e-16 * max(1.0, abs(f)):
                break
            f_trial, g_trial, data_trial = evaluate(trial)
            if np.isfinite(f_trial) and np.all(np.isfinite(g_trial)) and f_trial <= f + _ARMIJO * decrease:
                x, f, g, data = trial, f_trial, g_trial, data_trial
                history.append(f)
                break
            alpha /= 2
        else:
            decrease = 0.0
        if not decrease < -1e-16 * max(1.0, abs(f)):
            status = "solved_acceptable" if projected <= 100 * tolerance else "failed"
            return NewtonResult(x, f, status, "no step decreases the objective any further", iterations, projected)


def _symmetric_rank_one_update(correction: np.ndarray, H: np.ndarray, s: np.ndarray, y: np.ndarray) -> None:
    """correction += r rᵀ / (rᵀ s), r = y - (H + correction) s, in place; skipped when rᵀ s is tiny
    (the usual safeguard: |rᵀ s| ≥ 1e-8 |r| |s|)."""
    r = y - (H + correction) @ s
    denominator = r @ s
    if abs(denominator) > 1e-8 * np.linalg.norm(r) * np.linalg.norm(s):
        correction += np.outer(r, r) / denominator


def _regularised_cholesky(H: np.ndarray, delta_last: float):
    """Cholesky factor of H + delta·s·I with the least delta tried that works; returns (factor, delta_last).

    delta = 0 first; then delta_last/3 (or 1e-4 if no regularisation was needed before), growing by 8
    (by 100 the first time), as IPOPT does. s = max |diag H| makes delta relative.
    """
    try:
        return scipy.linalg.cho_factor(H, check_finite=False), delta_last
    except scipy.linalg.LinAlgError:
        pass
    diagonal = np.diag(H)
    scale = max(float(np.max(np.abs(diagonal))), np.finfo(float).tiny)
    shifted = H.copy()
    delta = 1e-4 if delta_last == 0 else max(delta_last / 3, 1e-20)
    growth = 100.0 if delta_last == 0 else 8.0
    while delta < 1e20:
        np.fill_diagonal(shifted, diagonal + delta * scale)
        try:
            return scipy.linalg.cho_factor(shifted, check_finite=False), delta
        except scipy.linalg.LinAlgError:
            delta *= growth
    return None, delta_last
