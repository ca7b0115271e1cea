"""Standard errors of a maximum-(pseudo-)likelihood fit from central finite differences.

With f_k(u) the negative log-likelihood of trial k and F = Σ_k f_k, at the optimum u*:

- Laplace: cov(u) = H⁻¹ with H the Hessian of F. Right when F is the full likelihood of the data.
- Robust (sandwich, Godambe): cov(u) = H⁻¹ S H⁻¹ with S = Σ_k g_k g_kᵀ and g_k the gradient of f_k. Right
  for a pseudo-likelihood whose trials are independent but whose samples within a trial are not, as in
  :mod:`comanip.fitting.likelihood`; with correlated samples the Laplace errors are too small.

Both come from the same 2p + 4·p(p-1)/2 evaluations around u* (step in transformed units), so the robust
errors cost nothing extra. Errors in natural units follow by the delta method (see
:meth:`comanip.fitting.parameters.ParameterSpace.natural_std_errors`); for log-parameters a relative error.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from itertools import combinations

import numpy as np


@dataclass(frozen=True)
class Curvature:
    """Finite-difference derivatives at u* (p transformed parameters, K trials)."""

    hessian: np.ndarray
    """Hessian of the summed NLL (p, p)."""
    scores: np.ndarray
    """Gradient of each trial's NLL (K, p)."""

    def laplace_std(self) -> np.ndarray:
        """sqrt(diag(H⁻¹)) (p,); NaN when H is not positive definite."""
        inverse = self._inverse()
        return np.full(len(self.hessian), np.nan) if inverse is None else np.sqrt(np.diag(inverse))

    def robust_std(self) -> np.ndarray:
        """sqrt(diag(H⁻¹ S H⁻¹)) (p,); NaN when H is not positive definite."""
        inverse = self._inverse()
        if inverse is None:
            return np.full(len(self.hessian), np.nan)
        return np.sqrt(np.diag(inverse @ (self.scores.T @ self.scores) @ inverse))

    def _inverse(self) -> np.ndarray | None:
        if not np.all(np.isfinite(self.hessian)) or np.linalg.eigvalsh(self.hessian).min() <= 0:
            return None
        return np.linalg.inv(self.hessian)


def curvature(per_trial: Callable[[np.ndarray], np.ndarray], u: np.ndarray, step: float) -> Curvature:
    """Central-difference Hessian of Σ per_trial(u) and per-trial gradients at u (p,), step in units of u."""
    u = np.asarray(u, dtype=float)
    p = len(u)
    e = np.eye(p) * step
    f0 = np.asarray(per_trial(u))
    plus = np.array([per_trial(u + e[i]) for i in range(p)])
    minus = np.array([per_trial(u - e[i]) for i in range(p)])
    hessian = np.diag((plus + minus - 2 * f0).sum(axis=1) / step**2)
    for i, j in combinations(range(p), 2):
        corners = [np.sum(per_trial(u + a * e[i] + b * e[j])) for a, b in ((1, 1), (1, -1), (-1, 1), (-1, -1))]
        hessian[i, j] = hessian[j, i] = (corners[0] - corners[1] - corners[2] + corners[3]) / (4 * step**2)
    return Curvature(hessian, ((plus - minus) / (2 * step)).T)
