"""The goal, duration and onset of a reach in progress, fitted to its observed prefix with a fixed shape.

Observed: times t_k (s), hand positions x_k (m) and velocities v_k (m/s), k = 1..K, from a hand at rest at
x_0. The reach follows a :class:`~comanip.estimation.reach_profile.ReachProfile` r at its own pace: x_k =
x_0 + Delta r(phi_k), v_k = Delta r'(phi_k) / T, phi_k = (t_k - t_0) / T, with the displacement Delta = g - x_0
(d,), the movement time T and the onset t_0 unknown. For each (T, t_0) on a grid the model is linear in
Delta, so Delta is its weighted least-squares solution (variable projection) and the pair with the smallest

    chi²(T, t_0) = sum_k |x_k - x_0 - Delta r_k|² / sigma_x² + |v_k - Delta r'_k / T|² / sigma_v²

fits best; the best grid pair is refined by a Nelder–Mead search over (log T, t_0). sigma_x is
``position_noise`` times the hand's largest displacement so far and sigma_v ``velocity_noise`` times its
largest speed so far, so positions and velocities weigh alike at any scale.

The estimate is the mean of a posterior over the grid (times an optional prior on log T) whose noise scale is
estimated from the residual (s² = chi²_min / (number of observed numbers - d - 2), at least ``SHAPE_ERROR``²), each pair weighed
by exp(-(chi² - chi²_min) / (2 s²)); its covariance is the spread of the pairs' Delta plus each one's
least-squares covariance. ``timing_evidence`` compares a
given (T, t_0) with the best: (chi²(T, t_0) - chi²_min) / s², about chi²-distributed with 2 degrees of freedom
when the given timing is the true one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from comanip.estimation.reach_profile import ReachProfile


REFINEMENT_EVALUATIONS = 80
"""Largest number of Nelder–Mead iterations refining the best grid pair."""
SHAPE_ERROR = 0.1
"""The smallest noise scale s of the fit's posterior, in units of the weights' sigma: a shape is taken to be
known to a tenth of sigma_x (0.3 % of the displacement) even where it fits the observations better."""


@dataclass(frozen=True)
class FitSettings:
    """The weights and grids of :func:`fit_profile` (module docstring)."""

    position_noise: float = 0.03
    """sigma_x as a fraction of the hand's largest displacement from the start so far."""
    velocity_noise: float = 0.1
    """sigma_v as a fraction of the hand's largest speed so far."""
    durations: tuple[float, float, int] = (0.1, 4.0, 40)
    """Grid of movement times T: (shortest s, longest s, points), geometric."""
    onset_window: tuple[float, float, int] = (-0.15, 0.15, 11)
    """Grid of onsets t_0 around the detected onset: (earliest offset s, latest offset s, points)."""


@dataclass(frozen=True)
class ProfileFit:
    """The best grid point of a shape fit (module docstring)."""

    goal: np.ndarray
    """x_0 + Delta (d,), m."""
    duration: float
    """T (s)."""
    onset: float
    """t_0 (s)."""
    misfit: float
    """chi² per observed number."""
    covariance: np.ndarray
    """Covariance of ``goal`` (d, d), m² (module docstring)."""
    timing_evidence: float | None = None
    """(chi² at the ``timing`` asked for - chi²_min) / s²; None when no timing was asked for."""


def detected_onset(t: np.ndarray, speed: np.ndarray, threshold: float) -> float | None:
    """The first time (s) of ``t`` (K,) at which the speed (K,) exceeds ``threshold`` (m/s), or None."""
    moving = np.flatnonzero(speed > threshold)
    return None if moving.size == 0 else float(t[moving[0]])


def fit_profile(t, position, velocity, start, profile: ReachProfile, onset: float,
                settings: FitSettings = FitSettings(), timing: tuple[float, float] | None = None,
                duration_prior: tuple[float, float] | None = None) -> ProfileFit:
    """Fit ``profile`` to observations (module docstring).

    Args:
        t: observation times (K,), s.
        position: hand positions (K, d), m.
        velocity: hand velocities (K, d), m/s.
        start: the hand's rest position x_0 (d,), m.
        profile: the shape r.
        onset: the detected onset (s), the centre of the onset grid.
        settings: weights and grids.
        timing: a (T s, t_0 s) to compare with the best fit (``timing_evidence``).
        duration_prior: (T_ref s, std): log T ~ N(log T_ref, std²) weighs the grid; None: no prior.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(position, dtype=float) - start
    v = np.asarray(velocity, dtype=float)
    wx = 1.0 / (settings.position_noise * max(float(np.sqrt((y * y).sum(axis=1).max())), 1e-6)) ** 2
    wv = 1.0 / (settings.velocity_noise * max(float(np.sqrt((v * v).sum(axis=1).max())), 1e-6)) ** 2
    total = wx * (y * y).sum() + wv * (v * v).sum()

    def solve(T, T0):
        """(Delta (G, d), chi² (G,), normal (G,)) at the pairs (T (G,), t_0 (G,))."""
        r, dr = profile((t[None, :] - T0[:, None]) / T[:, None])
        dr = dr / T[:, None]
        normal = np.maximum(wx * (r * r).sum(axis=1) + wv * (dr * dr).sum(axis=1), 1e-300)
        delta = (wx * r @ y + wv * dr @ v) / normal[:, None]
        return delta, np.maximum(total - normal * (delta * delta).sum(axis=1), 0.0), normal

    durations = np.geomspace(*settings.durations[:2], settings.durations[2])
    onsets = onset + np.linspace(*settings.onset_window[:2], settings.onset_window[2])
    TT, T0 = (a.ravel() for a in np.meshgrid(durations, onsets, indexing="ij"))
    delta, chi2, normal = solve(TT, T0)
    start_point = int(np.argmin(chi2))
    refined = minimize(lambda p: float(solve(np.array([math.exp(p[0])]), np.array([p[1]]))[1][0]),
                       [math.log(TT[start_point]), T0[start_point]], method="Nelder-Mead",
                       options={"xatol": 1e-4, "fatol": 1e-12, "maxiter": REFINEMENT_EVALUATIONS})
    T_best, t0_best = math.exp(refined.x[0]), float(refined.x[1])
    extra = solve(np.array([T_best]), np.array([t0_best]))
    delta, chi2, normal = np.r_[delta, extra[0]], np.r_[chi2, extra[1]], np.r_[normal, extra[2]]
    TT, T0 = np.r_[TT, T_best], np.r_[T0, t0_best]
    best = int(np.argmin(chi2))
    d = y.shape[1]
    s2 = max(float(chi2[best]) / max(y.size + v.size - d - 2, 1), SHAPE_ERROR**2)
    log_weight = -0.5 * (chi2 - chi2[best]) / s2
    if duration_prior is not None:
        log_weight -= 0.5 * ((np.log(TT) - math.log(duration_prior[0])) / duration_prior[1]) ** 2
    weight = np.exp(log_weight - log_weight.max())
    weight /= weight.sum()
    mean = weight @ delta
    spread = delta - mean
    covariance = (weight[:, None] * spread).T @ spread + s2 * float(weight @ (1.0 / normal)) * np.eye(d)
    evidence = None
    if timing is not None:
        evidence = (float(solve(np.array([timing[0]]), np.array([timing[1]]))[1][0]) - float(chi2[best])) / s2
    return ProfileFit(goal=np.asarray(start, dtype=float) + mean, duration=float(weight @ TT), onset=float(weight @ T0),
                      misfit=float(chi2[best]) / max(y.size + v.size, 1), covariance=covariance, timing_evidence=evidence)
