"""Whether a tracked hand is at rest, judged from its positions, not its velocities.

A tracker's velocities are differences of noisy positions: 1 mm of position noise at 100 Hz is about 0.1 m/s
of velocity noise, as fast as the slow end of a reach. So rest is judged on positions (m) at times (s):

- the hand **has left its start** once a position lies farther than ``radius`` from the start;
- the hand **rests** when every position of the last ``window`` seconds lies within ``radius`` of their mean,
  and those positions span at least the window (a hand seen for a shorter time is not known to rest).

``REST_RADIUS_M`` is well above a motion-capture or camera tracker's noise (about 0.1–2 mm) and well below any
reach's amplitude; ``REST_WINDOW_S`` is a tenth of a second, the time a person's hand stays still between
the sub-movements of one reach only rarely exceeds.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

REST_RADIUS_M = 0.005
"""Positions within this distance (m) of their mean, or of the start, count as still."""
REST_WINDOW_S = 0.1
"""How long (s) the positions must stay still for the hand to rest."""


def lost_sample(value) -> bool:
    """Whether a tracker's position or velocity is a sample it lost: given, but all NaN."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return array.size > 0 and bool(np.all(np.isnan(array)))


def has_left(position: np.ndarray, start: np.ndarray, radius: float = REST_RADIUS_M) -> bool:
    """Whether any position (K, d) m lies farther than ``radius`` (m) from ``start`` (d,) m."""
    offset = position - start
    return bool(np.any((offset * offset).sum(axis=1) > radius * radius))


class FittedVelocity(NamedTuple):
    """The velocity of a straight line fitted to positions."""

    velocity: np.ndarray
    """(d,) m/s."""
    standard_error: float
    """Per axis (m/s), from the positions' scatter about the line (pooled over the axes)."""


def fitted_velocity(t: np.ndarray, position: np.ndarray) -> FittedVelocity:
    """The velocity (d,) m/s of a straight line fitted to positions (K, d) m at times (K,) s (K ≥ 3), and its
    standard error."""
    times = t - t.mean()
    offset = position - position.mean(axis=0)
    spread = float(times @ times)
    slope = times @ offset / spread
    residual = offset - np.outer(times, slope)
    return FittedVelocity(slope, float(np.sqrt(float((residual * residual).sum()) / max(len(times) - 2, 1) / spread)))


def too_far_apart_to_rest(first, last, radius: float = REST_RADIUS_M) -> bool:
    """True when two positions (d,) m of one window lie more than twice ``radius`` (m) apart, so that no mean lies
    within ``radius`` of both and the hand does not rest over that window (:func:`resting_position` says None);
    a test without arrays, for a stream's every sample."""
    gap = 0.0
    for a, b in zip(first, last):
        gap += (a - b) * (a - b)
    return gap > 4.0 * radius * radius * (1.0 + 1e-9)


def resting_position(t: np.ndarray, position: np.ndarray, window: float = REST_WINDOW_S, radius: float = REST_RADIUS_M,
                     creep: float = np.inf) -> np.ndarray | None:
    """The mean position (d,) m of the last ``window`` s when the hand rests there (module docstring), else None.

    Args:
        t: times (K,) s, increasing; position: (K, d) m.
        creep: a hand whose velocity over the window (:func:`fitted_velocity`, m/s) is above this still moves,
            however small the radius it stays in (a slow final correction); a velocity within three standard
            errors of zero counts as rest whatever ``creep`` is, since the tracker's noise cannot tell it from rest.
    """
    if len(t) < 3 or t[-1] - t[0] < window:
        return None
    first = int(np.searchsorted(t, t[-1] - window, side="left"))
    recent = position[first:]
    mean = recent.mean(axis=0)
    offset = recent - mean
    if len(recent) < 3 or not bool(np.all((offset * offset).sum(axis=1) <= radius * radius)):
        return None
    slope, error = fitted_velocity(t[first:], recent)
    return mean if np.linalg.norm(slope) <= max(creep, 3.0 * error * np.sqrt(len(slope))) else None
