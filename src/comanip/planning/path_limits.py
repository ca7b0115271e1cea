"""Joint position and velocity limits on the planned mean path, by an augmented Lagrangian.

Constraints c(x) ≤ 0 on the mean state mu_i = [q_i; qdot_i] of steps i = 1..H:
q_min ≤ q_i ≤ q_max and |qdot_i| ≤ qdot_max (the body's limits; infinite ones are left out). Torque
limits are simple bounds and stay with the Newton method.

Most reaches never come near a limit, so the limits cost nothing until they bind: the Newton method
minimises

    L(x; y, rho) = f(x) + Σ_j ((max(0, y_j + rho c_j(x)))² - y_j²) / (2 rho)

and after each minimisation the multipliers become y ← max(0, y + rho c(x)) and rho grows tenfold while
the largest violation has not shrunk by a factor of four (the classical augmented Lagrangian; Nocedal &
Wright 2006, ch. 17.4, Algorithm 17.4 minimises inexactly in the same way). Once the limits hold, a last
round minimises to the full tolerance. A plan carries its final y and rho (``plan.extras``), and a solve warm-started
from it begins there. The Hessian of the penalty is its Gauss–Newton part rho Σ_active ∇c ∇cᵀ, exact up
to the curvature of the mean path; ∇c are rows of d mu_i / d tau, which the curvature object provides.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.planning.newton import NewtonResult, newton_minimize

LIMIT_TOLERANCE = 1e-6
"""Largest violation (rad or rad/s, m or m/s) a plan may keep."""
ROUGH_TOLERANCE = 1e-5
"""Gradient tolerance of the rounds before the limits hold (an inexact augmented Lagrangian: the
multipliers are still moving, so the tail of a tight minimisation would be wasted)."""


@dataclass(frozen=True)
class PathLimits:
    """Bounds on the mean state of steps 1..H: lower, upper (H, 2n); ±inf where a body has none."""

    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def of(cls, model) -> "PathLimits":
        body, H = model.body, model.H
        lower = np.tile(np.concatenate([body.q_min, -body.qdot_max]), (H, 1))
        upper = np.tile(np.concatenate([body.q_max, body.qdot_max]), (H, 1))
        return cls(lower, upper)

    @property
    def active(self) -> bool:
        """True when any limit is finite."""
        return bool(np.isfinite(self.lower).any() or np.isfinite(self.upper).any())

    def constraints(self, mean: np.ndarray) -> np.ndarray:
        """c (2, H, 2n) for the mean (H+1, 2n): [mu - upper, lower - mu]; ≤ 0 when the limits hold (-inf where none)."""
        return np.stack([mean[1:] - self.upper, self.lower - mean[1:]])

    def violation(self, mean: np.ndarray) -> float:
        return float(max(0.0, np.max(self.constraints(mean))))


@dataclass
class LimitedResult:
    """A Newton result for the objective within limits, with the multipliers to warm-start the next solve."""

    result: NewtonResult
    """f is the objective itself (not the Lagrangian); iterations are summed over the inner solves."""
    multipliers: np.ndarray | None
    """y (2, H, 2n) at the end (None for a body without limits)."""
    rho: float


def minimize_within_limits(curvature, limits: PathLimits, params: np.ndarray, x0: np.ndarray, lb: np.ndarray,
                           ub: np.ndarray, *, tolerance: float, max_iterations: int, secant: bool, expired,
                           multipliers: np.ndarray | None = None, rho: float = 1e2, max_outer: int = 8) -> LimitedResult:
    """Minimise the normalised objective of ``curvature`` over torque bounds and the path limits.

    ``max_iterations`` applies to each inner Newton solve.

    ``multipliers`` and ``rho`` from a previous, similar solve start the augmented Lagrangian where that
    one ended, so a warm solve whose limits bind like its predecessor's needs one inner solve. The status
    is 'limits_violated' when the limits still do not hold after ``max_outer`` updates.
    """
    options = dict(tolerance=tolerance, secant=secant, expired=expired)
    if not limits.active:
        result = newton_minimize(lambda x: curvature.evaluate(x, params), curvature.hessian, x0, lb, ub,
                                 max_iterations=max_iterations, **options)
        return LimitedResult(result, None, rho)
    y = np.zeros((2,) + limits.lower.shape) if multipliers is None else np.array(multipliers, dtype=float)
    x, iterations, violation = x0, 0, np.inf
    for _ in range(max_outer):
        # rounds that still move the multipliers need only a rough minimum; the last one polishes
        polish = violation <= LIMIT_TOLERANCE
        inner = dict(options, tolerance=tolerance if polish else max(tolerance, ROUGH_TOLERANCE))
        penalised = _AugmentedLagrangian(curvature, limits, params, y, rho)
        result = newton_minimize(penalised.evaluate, penalised.hessian, x, lb, ub, max_iterations=max_iterations, **inner)
        x, iterations = result.x, iterations + result.iterations
        c = limits.constraints(curvature.trajectory(curvature.evaluate(x, params)[2])[0])
        new_violation = float(max(0.0, np.max(c)))
        if result.status in ("max_wall_time", "failed", "max_iterations") or (polish and new_violation <= LIMIT_TOLERANCE):
            violation = new_violation
            break
        y = np.maximum(0.0, y + rho * c)
        if new_violation > LIMIT_TOLERANCE and new_violation > 0.25 * violation:
            rho *= 10
        violation = new_violation
    status, message = result.status, result.message
    if violation > LIMIT_TOLERANCE and status not in ("max_wall_time", "failed", "max_iterations"):
        status, message = "limits_violated", f"joint limits violated by {violation:.3g} after the augmented Lagrangian"
    final = NewtonResult(x, curvature.value(x, params), status, message, iterations, result.projected_gradient)
    return LimitedResult(final, y, rho)


class _AugmentedLagrangian:
    """L(x; y, rho) of the module docstring, evaluated with the curvature object's pieces."""

    def __init__(self, curvature, limits: PathLimits, params, multipliers, rho: float):
        self.curvature, self.limits, self.params = curvature, limits, params
        self.multipliers, self.rho = multipliers, rho

    def evaluate(self, x):
        f, g, data = self.curvature.evaluate(x, self.params)
        mean, _ = self.curvature.trajectory(data)
        shifted = np.maximum(0.0, self.multipliers + self.rho * self.limits.constraints(mean))  # (2, H, 2n)
        f = f + (np.sum(shifted**2) - np.sum(self.multipliers**2)) / (2 * self.rho)
        if np.any(shifted > 0):
            T = self.curvature.mean_sensitivities(data)[1:]  # (H, 2n, H, n): d mu_i / d tau
            weight = shifted[0] - shifted[1]  # dc/dmu is +1 for upper, -1 for lower bounds
            g = g + np.einsum("ir,irkj->kj", weight, T).ravel()
            data = (data, T, shifted > 0)
        else:
            data = (data, None, None)
        return f, g, data

    def hessian(self, data):
        inner, T, active = data
        H = self.curvature.hessian(inner)
        if T is not None:
            # rows of active constraints: upper and lower share ∇mu rows (their sign squares away)
            rows = T.reshape(-1, H.shape[0])[(active[0] | active[1]).ravel()]
            H += self.rho * rows.T @ rows
        return H
