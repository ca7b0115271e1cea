"""The goal, duration and onset of a reach in progress, fitted to its observed prefix with a fixed shape.

Observed: times t_k (s), hand positions x_k (m) and velocities v_k (m/s), k = 1..K, from a hand at rest at
x_0. The reach follows a :class:`~comanip.estimation.reach_profile.ReachProfile` r at its own pace: x_k =
x_0 + Delta r(phi_k), v_k = Delta r'(phi_k) / T, phi_k = (t_k - t_0) / T, with the displacement Delta = g - x_0
(d,), the movement time T and the onset t_0 unknown. For each (T, t_0) on a grid the model is linear in
Delta, so Delta is its weighted least-squares solution (variable projection) and the pair with the smallest

    chi²(T, t_0) = sum_k |x_k - x_0 - Delta r_k|² / sigma_x² + |v_k - Delta r'_k / T|² / sigma_v²

gives the fit. sigma_x is ``position_noise`` times the hand's largest displacement so far and sigma_v
``velocity_noise`` times its largest speed so far, so positions and velocities weigh alike at any scale.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.estimation.reach_profile import ReachProfile


@dataclass(frozen=True)
class FitSettings:
    """The weights and grids of :func:`fit_profile` (module docstring)."""

    position_noise: float = 0.03
    """sigma_x as a fraction of the hand's largest displacement from the start so far."""
    velocity_noise: float = 0.1
    """sigma_v as a fraction of the hand's largest speed so far."""
    durations: tuple[float, float, int] = (0.1, 4.0, 48)
    """Grid of movement times T: (shortest s, longest s, points), geometric."""
    onset_window: tuple[float, float, int] = (-0.15, 0.03, 10)
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


def detected_onset(t: np.ndarray, speed: np.ndarray, threshold: float) -> float | None:
    """The first time (s) of ``t`` (K,) at which the speed (K,) exceeds ``threshold`` (m/s), or None."""
    moving = np.flatnonzero(speed > threshold)
    return None if moving.size == 0 else float(t[moving[0]])


def fit_profile(t, position, velocity, start, profile: ReachProfile, onset: float,
                settings: FitSettings = FitSettings()) -> ProfileFit:
    """Fit ``profile`` to observations (module docstring).

    Args:
        t: observation times (K,), s.
        position: hand positions (K, d), m.
        velocity: hand velocities (K, d), m/s.
        start: the hand's rest position x_0 (d,), m.
        profile: the shape r.
        onset: the detected onset (s), the centre of the onset grid.
        settings: weights and grids.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(position, dtype=float) - start
    v = np.asarray(velocity, dtype=float)
    wx = 1.0 / (settings.position_noise * max(float(np.sqrt((y * y).sum(axis=1).max())), 1e-6)) ** 2
    wv = 1.0 / (settings.velocity_noise * max(float(np.sqrt((v * v).sum(axis=1).max())), 1e-6)) ** 2
    T = np.geomspace(*settings.durations[:2], settings.durations[2])
    t0 = onset + np.linspace(*settings.onset_window[:2], settings.onset_window[2])
    TT, T0 = (a.ravel() for a in np.meshgrid(T, t0, indexing="ij"))                # (G,)
    r, dr = profile((t[None, :] - T0[:, None]) / TT[:, None])                       # (G, K)
    dr = dr / TT[:, None]
    normal = np.maximum(wx * (r * r).sum(axis=1) + wv * (dr * dr).sum(axis=1), 1e-300)
    delta = (wx * r @ y + wv * dr @ v) / normal[:, None]                            # (G, d)
    chi2 = (wx * (y * y).sum() + wv * (v * v).sum()) - normal * (delta * delta).sum(axis=1)
    best = int(np.argmin(chi2))
    return ProfileFit(goal=np.asarray(start, dtype=float) + delta[best], duration=float(TT[best]), onset=float(T0[best]),
                      misfit=max(float(chi2[best]), 0.0) / max(y.size + v.size, 1))
