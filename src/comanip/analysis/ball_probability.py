"""Probability that a Gaussian point lands in a ball: P(||y|| ≤ r) for y ~ N(m, S) in d dimensions.

This is the closed-form hit rate of a reach: y is the hand's offset from the goal at the movement time, m and
S its predicted mean and covariance, r the goal radius w. It is exact for a Gaussian up to quadrature error
(below 1e-8), for any d, isotropic or not, and for singular S.

In the eigenbasis of S the coordinates are independent, y_j = m_j + s_j z_j with z_j standard normal
(m now the rotated offset, s_j² the eigenvalues, largest first), and the probability follows by peeling off
one coordinate at a time:

    P(m, s, r) = ∫_{-r}^{r} N(y_1; m_1, s_1²) · P(m_{2:}, s_{2:}, sqrt(r² − y_1²)) dy_1,
    P(m_d, s_d, r) = Φ((r − m_d)/s_d) − Φ((−r − m_d)/s_d)            (one coordinate left).

The outer integral is cut to m_1 ± 9 s_1 (the Gaussian mass outside is below 1e-18); coordinates with no
spread (s_j = 0) are fixed at m_j. With s_j all equal the result is the noncentral chi-square CDF.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import quad
from scipy.special import ndtr

_TAIL = 9.0
"""Half-width, in standard deviations, of the interval the outer integral covers."""


def ball_probability(mean, cov, radius: float) -> float:
    """P(||y|| ≤ radius) for y ~ N(mean, cov): mean (d,) m, cov (d, d) m² symmetric positive semi-definite,
    radius > 0 m. Returns a probability in [0, 1]."""
    mean = np.atleast_1d(np.asarray(mean, dtype=float))
    cov = np.atleast_2d(np.asarray(cov, dtype=float))
    d = mean.size
    if mean.ndim != 1 or cov.shape != (d, d):
        raise ValueError(f"mean must be (d,) and cov (d, d), got shapes {mean.shape} and {cov.shape}")
    if not (np.all(np.isfinite(mean)) and np.all(np.isfinite(cov))):
        raise ValueError("mean and cov must be finite")
    if isinstance(radius, bool) or not (np.isfinite(radius) and radius > 0):
        raise ValueError(f"radius must be a finite number > 0 (m), got {radius!r}")
    values, vectors = np.linalg.eigh(0.5 * (cov + cov.T))
    if values.min() < -1e-9 * np.abs(values).max():
        raise ValueError(f"cov must be positive semi-definite, got eigenvalues {values.tolist()}")
    order = np.argsort(values)[::-1]
    spread = np.sqrt(np.clip(values[order], 0.0, None))
    offset = vectors[:, order].T @ mean
    return float(np.clip(_inside(offset, spread, float(radius)), 0.0, 1.0))


def _inside(offset: np.ndarray, spread: np.ndarray, radius: float) -> float:
    """P(||offset + spread ⊙ z|| ≤ radius), z standard normal; spread (k,) in descending order."""
    m, s = offset[0], spread[0]
    if s == 0.0:  # every remaining coordinate is fixed (spread is descending)
        return float(np.linalg.norm(offset) <= radius)
    if len(offset) == 1:
        return float(ndtr((radius - m) / s) - ndtr((-radius - m) / s))
    low, high = max(-radius, m - _TAIL * s), min(radius, m + _TAIL * s)
    if low >= high:
        return 0.0

    def integrand(y: float) -> float:
        density = math.exp(-0.5 * ((y - m) / s) ** 2) / (s * math.sqrt(2 * math.pi))
        return density * _inside(offset[1:], spread[1:], math.sqrt(max(radius**2 - y**2, 0.0)))

    value, _ = quad(integrand, low, high, epsabs=1e-10, epsrel=1e-8, limit=200)
    return value
