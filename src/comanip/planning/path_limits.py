"""Joint position and velocity limits on the planned mean path, as constraints for the Newton method.

Constraints c(x) ≤ 0 on the mean state mu_i = [q_i; qdot_i] of steps i = 1..H:
q_min ≤ q_i ≤ q_max and |qdot_i| ≤ qdot_max (the body's limits; infinite ones are -inf rows that never
enter the working set). Torque limits are bounds on x itself. The rows of the constraints' Jacobian are
rows of d mu_i / d tau, exact along the mean (the curvature object computes them from the step
Jacobians). The Newton method (:func:`comanip.optim.active_set_newton.newton_minimize`) keeps the few binding
ones in its working set; most reaches bind none and pay nothing.

An augmented Lagrangian (penalty rounds with multiplier updates) needs more Newton iterations per warm arm
solve than the working set.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

LIMIT_TOLERANCE = 1e-6
"""Largest violation (rad or rad/s, m or m/s) a plan may keep."""


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

    @cached_property
    def active(self) -> bool:
        """True when any limit is finite."""
        return bool(np.isfinite(self.lower).any() or np.isfinite(self.upper).any())

    def constraints(self, mean: np.ndarray) -> np.ndarray:
        """c (2, H, 2n) for the mean (H+1, 2n): [mu - upper, lower - mu]; ≤ 0 when the limits hold (-inf where none)."""
        return np.stack([mean[1:] - self.upper, self.lower - mean[1:]])

    def violation(self, mean: np.ndarray) -> float:
        return float(max(0.0, np.max(self.constraints(mean))))

    def for_newton(self, curvature):
        """The callback :func:`newton_minimize` takes: (x, data) -> (c (2·H·2n,), rows(indices))."""

        def constraints(x, data):
            c = self.constraints(curvature.mean_path(data)).ravel()

            def rows(indices):
                T = curvature.mean_sensitivities(data)[1:].reshape(c.size // 2, -1)  # d mu_i / d tau, rows (i, entry)
                upper = indices < c.size // 2
                return np.where(upper[:, None], 1.0, -1.0) * T[np.where(upper, indices, indices - c.size // 2)]

            return c, rows

        return constraints
