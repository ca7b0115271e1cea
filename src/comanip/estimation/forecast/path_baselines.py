"""Simple forecasts of where a moving hand will be, the yardsticks of :mod:`comanip.estimation.forecast.hand_forecast`.

Each takes the hand's state now (position x (d,) m, velocity v (d,) m/s, acceleration a (d,) m/s²) and gives
its position at ``lead`` times (M,) s from now, (M, d) m:

- :func:`hand_stays`: x;
- :func:`constant_velocity`: x + v s;
- :func:`constant_acceleration`: x + v s + a s² / 2;
- :func:`minimum_jerk_to`: the minimum-jerk path from (x, v, a) to rest at a goal g at a stop time T from now,
  then at g (the quintic with those six boundary conditions).

:func:`recent_acceleration` estimates a from the last velocities, causally.
"""

from __future__ import annotations

import numpy as np

ACCELERATION_WINDOW_S = 0.04
"""Span (s) of the last velocities whose least-squares slope is the acceleration."""


def _leads(lead) -> np.ndarray:
    lead = np.atleast_1d(np.asarray(lead, dtype=float))
    if lead.ndim != 1 or not np.all(np.isfinite(lead)) or np.any(lead < 0):
        raise ValueError(f"lead must be times ≥ 0 s from now, a number or a 1-D array; got {lead!r}")
    return lead[:, None]


def hand_stays(position, lead) -> np.ndarray:
    """x at every lead: (M, d) m."""
    return np.broadcast_to(np.asarray(position, dtype=float), (len(_leads(lead)), np.size(position))).copy()


def constant_velocity(position, velocity, lead) -> np.ndarray:
    """x + v s (M, d) m for leads s (M,) s."""
    return np.asarray(position, dtype=float) + _leads(lead) * np.asarray(velocity, dtype=float)


def constant_acceleration(position, velocity, acceleration, lead) -> np.ndarray:
    """x + v s + a s² / 2 (M, d) m for leads s (M,) s."""
    s = _leads(lead)
    return np.asarray(position, dtype=float) + s * np.asarray(velocity, dtype=float) + 0.5 * s**2 * np.asarray(acceleration, dtype=float)


def minimum_jerk_to(position, velocity, acceleration, goal, stop_in: float, lead) -> np.ndarray:
    """The minimum-jerk path (M, d) m from x, v, a now to rest at ``goal`` (d,) m ``stop_in`` s from now, at leads
    (M,) s; at the goal from then on. ``stop_in`` ≤ 0 is read as one millisecond."""
    s = _leads(lead)
    T = max(float(stop_in), 1e-3)
    x0, v0, a0 = (np.asarray(value, dtype=float) for value in (position, velocity, acceleration))
    g = np.asarray(goal, dtype=float)
    # quintic x(s) = x0 + v0 s + a0 s²/2 + c3 s³ + c4 s⁴ + c5 s⁵ with x(T) = g, x'(T) = x''(T) = 0
    gap = g - x0 - v0 * T - 0.5 * a0 * T**2
    slope = -v0 - a0 * T
    bend = -a0
    c3 = (10 * gap - 4 * slope * T + 0.5 * bend * T**2) / T**3
    c4 = (-15 * gap + 7 * slope * T - bend * T**2) / T**4
    c5 = (6 * gap - 3 * slope * T + 0.5 * bend * T**2) / T**5
    u = np.minimum(s, T)
    return x0 + v0 * u + 0.5 * a0 * u**2 + c3 * u**3 + c4 * u**4 + c5 * u**5


def recent_acceleration(t, velocity, window_s: float = ACCELERATION_WINDOW_S) -> np.ndarray:
    """The least-squares slope (d,) m/s² of the velocities (K, d) m/s at times (K,) s over the last ``window_s``
    (at least the last two samples); zeros with fewer than two."""
    t, velocity = np.asarray(t, dtype=float), np.asarray(velocity, dtype=float)
    if len(t) < 2:
        return np.zeros(velocity.shape[1])
    first = min(int(np.searchsorted(t, t[-1] - window_s - 1e-9)), len(t) - 2)
    dt = t[first:] - t[first:].mean()
    return dt @ (velocity[first:] - velocity[first:].mean(axis=0)) / float(dt @ dt)
