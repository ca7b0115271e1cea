"""The goal, duration and onset of a reach in progress, fitted to its observed prefix with a fixed shape.

Observed: times t_k (s), hand positions x_k (m) and velocities v_k (m/s), k = 1..K, from a hand at rest at
x_0. The reach follows a :class:`~comanip.estimation.model_reaches.reach_profile.ReachProfile` r at its own pace: x_k =
x_0 + Delta r(phi_k), v_k = Delta r'(phi_k) / T, phi_k = (t_k - t_0) / T, with the displacement Delta = g - x_0
(d,), the movement time T and the onset t_0 unknown. For each (T, t_0) on a grid the model is linear in
Delta, so Delta is its weighted least-squares solution (variable projection) and the pair with the smallest

    chi²(T, t_0) = sum_k |x_k - x_0 - Delta r_k|² / sigma_x² + |v_k - Delta r'_k / T|² / sigma_v²

fits best; the best grid pair is refined by a pattern search over (log T, t_0). sigma_x is
``position_noise`` times the hand's largest displacement so far and sigma_v ``velocity_noise`` times its
largest speed so far, so positions and velocities weigh alike at any scale.

The estimate is the mean of a posterior over the grid (times an optional prior on log T) whose noise scale is
estimated from the residual (s² = chi²_min / (number of observed numbers - d - 2), at least ``SHAPE_ERROR``²), each pair weighed
by exp(-(chi² - chi²_min) / (2 s²)); its covariance is the spread of the pairs' Delta plus each one's
least-squares covariance (the points the pattern search visited join the grid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.estimation.model_reaches.reach_profile import ReachProfile


REFINEMENT_ROUNDS = 24
"""Largest number of pattern-search rounds refining the best grid pair."""
REFINED_STEPS = (2e-3, 5e-4)
"""The pattern search ends when its steps in log T and t_0 (s) are below these."""
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


def onset_index(speed: np.ndarray, threshold: float) -> int | None:
    """The index of the first speed (K,) above ``threshold`` (m/s), or None."""
    moving = np.flatnonzero(speed > threshold)
    return None if moving.size == 0 else int(moving[0])


def detected_onset(t: np.ndarray, speed: np.ndarray, threshold: float) -> float | None:
    """The first time (s) of ``t`` (K,) at which the speed (K,) exceeds ``threshold`` (m/s), or None."""
    first = onset_index(speed, threshold)
    return None if first is None else float(t[first])


def fit_profile(t, position, velocity, start, profile: ReachProfile, onset: float,
                settings: FitSettings = FitSettings(), duration_prior: tuple[float, float] | None = None) -> ProfileFit:
    """Fit ``profile`` to observations (module docstring).

    Args:
        t: observation times (K,), s.
        position: hand positions (K, d), m.
        velocity: hand velocities (K, d), m/s.
        start: the hand's rest position x_0 (d,), m.
        profile: the shape r.
        onset: the detected onset (s), the centre of the onset grid.
        settings: weights and grids.
        duration_prior: (T_ref s, std): log T ~ N(log T_ref, std²) weighs the grid; None: no prior.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(position, dtype=float) - start
    v = np.asarray(velocity, dtype=float)
    wx = 1.0 / (settings.position_noise * max(float(np.sqrt((y * y).sum(axis=1).max())), 1e-6)) ** 2
    wv = 1.0 / (settings.velocity_noise * max(float(np.sqrt((v * v).sum(axis=1).max())), 1e-6)) ** 2
    total = wx * (y * y).sum() + wv * (v * v).sum()

    def solve(log_T, T0):
        """(Delta (G, d), chi² (G,), normal (G,)) at the pairs (log T (G,), t_0 (G,))."""
        T = np.exp(log_T)
        r, dr = profile((t[None, :] - T0[:, None]) / T[:, None])
        dr = dr / T[:, None]
        normal = np.maximum(wx * (r * r).sum(axis=1) + wv * (dr * dr).sum(axis=1), 1e-300)
        delta = (wx * r @ y + wv * dr @ v) / normal[:, None]
        return delta, np.maximum(total - normal * (delta * delta).sum(axis=1), 0.0), normal

    durations = np.linspace(*np.log(settings.durations[:2]), settings.durations[2])
    onsets = onset + np.linspace(*settings.onset_window[:2], settings.onset_window[2])
    LT, T0 = (a.ravel() for a in np.meshgrid(durations, onsets, indexing="ij"))
    delta, chi2, normal = solve(LT, T0)
    refined = _pattern_search(solve, LT[int(np.argmin(chi2))], T0[int(np.argmin(chi2))],
                              durations[1] - durations[0], onsets[1] - onsets[0])
    delta, chi2, normal = (np.r_[a, b] for a, b in zip((delta, chi2, normal), refined[2:]))
    LT, T0 = np.r_[LT, refined[0]], np.r_[T0, refined[1]]
    best = int(np.argmin(chi2))
    d = y.shape[1]
    s2 = max(float(chi2[best]) / max(y.size + v.size - d - 2, 1), SHAPE_ERROR**2)
    log_weight = -0.5 * (chi2 - chi2[best]) / s2
    if duration_prior is not None:
        log_weight -= 0.5 * ((LT - math.log(duration_prior[0])) / duration_prior[1]) ** 2
    weight = np.exp(log_weight - log_weight.max())
    weight /= weight.sum()
    mean = weight @ delta
    spread = delta - mean
    covariance = (weight[:, None] * spread).T @ spread + s2 * float(weight @ (1.0 / normal)) * np.eye(d)
    return ProfileFit(goal=np.asarray(start, dtype=float) + mean, duration=float(weight @ np.exp(LT)),
                      onset=float(weight @ T0), misfit=float(chi2[best]) / max(y.size + v.size, 1), covariance=covariance)


def _pattern_search(solve, log_T: float, t0: float, step_T: float, step_t0: float):
    """Refine (log T, t_0) from a grid point: each round evaluates the 3 × 3 stencil of the current steps around
    the best point (one vectorised call) and moves there, halving the steps when the centre stays best, until
    the steps fall below :data:`REFINED_STEPS`. Returns the arrays (log T (P,), t_0 (P,), Delta (P, d),
    chi² (P,), normal (P,)) of the points visited."""
    offsets = np.array([(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1)], dtype=float)
    visited = []
    for _ in range(REFINEMENT_ROUNDS):
        points = np.array([log_T, t0]) + offsets * [step_T, step_t0]
        values = solve(points[:, 0], points[:, 1])
        visited.append((points, values))
        k = int(np.argmin(values[1]))
        if k == 4:
            step_T, step_t0 = 0.5 * step_T, 0.5 * step_t0
            if step_T < REFINED_STEPS[0] and step_t0 < REFINED_STEPS[1]:
                break
        log_T, t0 = points[k]
    points = np.concatenate([p for p, _ in visited])
    return (points[:, 0], points[:, 1], *(np.concatenate([v[i] for _, v in visited]) for i in range(3)))
