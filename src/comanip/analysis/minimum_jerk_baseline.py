"""The minimum-jerk baseline (Flash & Hogan 1985) shown beside the model's reaches.

A minimum-jerk reach from rest to rest over duration T has speed (D/T) · 30 s²(1 - s)², s = t/T: a
symmetric bell with its peak at mid-movement. Its speed falls below a fraction f of the peak when
16 s²(1 - s)² = f, i.e. at s_f = (1 + sqrt(1 - sqrt(f)))/2 (0.9406 for f = 5 %), so its docs/formulation.md §6 movement
time is s_f · T and its asymmetry t_peak/MT is 0.5/s_f (0.532 for f = 5 %). The baseline for a reach is
the minimum-jerk reach with the same start, goal and docs/formulation.md §6 movement time: only the shape differs.
"""

from __future__ import annotations

import numpy as np

from comanip.analysis.speed_profile import SETTLING_FRACTION
from comanip.planning.starts.initial_guess import minimum_jerk


def minimum_jerk_settling_fraction(settling_fraction: float = SETTLING_FRACTION) -> float:
    """s_f (dimensionless): the fraction of its duration at which a rest-to-rest minimum-jerk reach's
    speed falls below settling_fraction of its peak."""
    if not 0 < settling_fraction < 1:
        raise ValueError(f"settling_fraction must be in (0, 1), got {settling_fraction!r}")
    return 0.5 * (1.0 + np.sqrt(1.0 - np.sqrt(settling_fraction)))


def minimum_jerk_asymmetry(settling_fraction: float = SETTLING_FRACTION) -> float:
    """t_peak/MT of a rest-to-rest minimum-jerk reach under the docs/formulation.md §6 movement time."""
    return 0.5 / minimum_jerk_settling_fraction(settling_fraction)


def minimum_jerk_velocity(start, goal, movement_time: float, t, start_velocity=None,
                          settling_fraction: float = SETTLING_FRACTION) -> np.ndarray:
    """Velocity (len(t), d) in m/s of the minimum-jerk reach from start (d,) m to rest at goal (d,) m.

    Its duration is movement_time / s_f, so that from rest its docs/formulation.md §6 movement time equals movement_time
    (s). start_velocity (d,) m/s (default 0) starts the quintic moving; the duration rule is kept.
    """
    start = np.atleast_1d(np.asarray(start, dtype=float))
    v0 = np.zeros_like(start) if start_velocity is None else np.atleast_1d(np.asarray(start_velocity, dtype=float))
    if not (np.isfinite(movement_time) and movement_time > 0):
        raise ValueError(f"movement_time must be a finite number > 0 (s), got {movement_time!r}")
    duration = movement_time / minimum_jerk_settling_fraction(settling_fraction)
    _, velocity, _ = minimum_jerk(start, v0, goal, duration, t)
    return velocity


def minimum_jerk_speed_fraction(t, movement_time: float, settling_fraction: float = SETTLING_FRACTION) -> np.ndarray:
    """Speed over peak speed, 16 s²(1 − s)² with s = t/T clipped to [0, 1], at times t (s, any shape) of the
    rest-to-rest minimum-jerk reach whose docs/formulation.md §6 movement time is movement_time (s), T = movement_time/s_f."""
    if not (np.isfinite(movement_time) and movement_time > 0):
        raise ValueError(f"movement_time must be a finite number > 0 (s), got {movement_time!r}")
    s = np.clip(np.asarray(t, dtype=float) * minimum_jerk_settling_fraction(settling_fraction) / movement_time, 0.0, 1.0)
    return 16.0 * s**2 * (1.0 - s) ** 2
