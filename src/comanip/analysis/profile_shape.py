"""Shape of a reach's velocity profile beyond its timing (:mod:`comanip.analysis.speed_profile`): how it
starts, how many peaks it has, whether the hand moves backwards, and whether it has stopped by the end.

For mean end-effector velocities v_i (T, d) at uniform times t_i (s) of a reach along the unit vector u,
with speed |v_i| and P the largest speed sample:

- onset: |v|(t_0 + onset_time) / P, interpolated linearly between samples. A reach from rest that speeds
  up gradually has a small value, one whose velocity steps up at the start a large one. The value depends
  on the movement time: a minimum-jerk reach scores 0.28 at MT = 0.3 s and 0.05 at MT = 0.8 s for
  onset_time = 50 ms, and stays below 0.15 only for MT ≥ 0.43 s
  (:func:`comanip.analysis.minimum_jerk_baseline.minimum_jerk_speed_fraction`);
- peaks: interior local maxima of |v| (|v_i| > |v_{i-1}| and |v_i| ≥ |v_{i+1}|) of at least
  peak_floor · P;
- reversal: min_i (v_i · u) / P, the most negative velocity along the reach relative to the peak speed
  (0 for a reach from rest that never moves backwards; negative after an overshoot and return);
- end speed: |v_{T-1}| / P.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

ONSET_TIME = 0.05
"""Time after the start at which the onset is measured (s)."""
PEAK_FLOOR = 0.1
"""Local maxima of the speed below this fraction of the peak are not counted as peaks."""


@dataclass(frozen=True)
class ProfileShape:
    """Shape numbers of one velocity profile; every ratio is relative to the largest speed sample."""

    onset: float
    """Speed onset_time after the start over the peak speed."""
    peaks: int
    """Local maxima of the speed of at least peak_floor times the peak."""
    reversal: float
    """Most negative velocity along the reach direction over the peak speed; 0 when the hand never moves backwards."""
    end_speed: float
    """Speed at the last sample over the peak speed."""

    def to_dict(self) -> dict:
        return asdict(self)


def profile_shape(t, velocity, direction, onset_time: float = ONSET_TIME, peak_floor: float = PEAK_FLOOR) -> ProfileShape:
    """Shape of a profile: t (T,) uniform times (s), velocity (T, d) m/s, direction (d,) of the reach (any
    length > 0); onset_time (s) within the profile, peak_floor in [0, 1)."""
    t = np.asarray(t, dtype=float)
    velocity = np.asarray(velocity, dtype=float)
    if velocity.ndim == 1:
        velocity = velocity[:, None]
    u = np.atleast_1d(np.asarray(direction, dtype=float))
    if t.ndim != 1 or len(t) < 3 or velocity.shape != (len(t), u.size):
        raise ValueError(f"t must be (T,) with T ≥ 3, velocity (T, d) and direction (d,); got shapes "
                         f"{t.shape}, {velocity.shape}, {u.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(velocity)) and np.all(np.isfinite(u)) and np.linalg.norm(u) > 0):
        raise ValueError("t, velocity and direction must be finite, direction non-zero")
    if not t[0] <= t[0] + onset_time <= t[-1]:
        raise ValueError(f"onset_time must lie within the profile (0 to {t[-1] - t[0]} s), got {onset_time!r}")
    if not 0 <= peak_floor < 1:
        raise ValueError(f"peak_floor must be in [0, 1), got {peak_floor!r}")
    speed = np.linalg.norm(velocity, axis=1)
    peak = speed.max()
    if peak == 0:
        raise ValueError("the profile never moves (its speed is zero throughout)")
    middle = speed[1:-1]
    maxima = (middle > speed[:-2]) & (middle >= speed[2:]) & (middle >= peak_floor * peak)
    along = velocity @ (u / np.linalg.norm(u))
    return ProfileShape(onset=float(np.interp(t[0] + onset_time, t, speed) / peak), peaks=int(maxima.sum()),
                        reversal=float(min(along.min(), 0.0) / peak), end_speed=float(speed[-1] / peak))
