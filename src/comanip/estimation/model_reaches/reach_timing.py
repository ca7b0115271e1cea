"""When a reach moves: its onset and movement time, and the model's plan played at them.

A plan's mean reach, from rest at t = 0, moves from its onset tau_on (the first step its speed reaches 5 % of its
peak) to its end tau_on + T_model (the step after it last does). A person may start later and move faster or
slower: played at a :class:`ReachTiming` (onset t_0 s, movement time T s), the plan runs

    x(t) = mu(tau),   tau = tau_on + (t - t_0) / p,   p = T / T_model,

so its velocities are the plan's divided by p, and its forces (the activation stages and the commands) by p²
(:func:`timed_plan`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

MOVING_FRACTION = 0.05
"""A reach moves while its speed is at least this fraction of its peak."""


@dataclass(frozen=True)
class ReachTiming:
    """When a person's reach moves, on the clock of their observations."""

    onset_s: float
    """t_0: when the hand starts to move (s)."""
    movement_time_s: float
    """T: from the onset to where the hand stops (s)."""


class MovementSpan(NamedTuple):
    """Where a sampled movement moves (module docstring)."""

    first: int
    """The first sample at 5 % of the peak speed or above."""
    last: int
    """The sample after the last one at 5 % of the peak or above (the final sample at most)."""


def movement_span(speed: np.ndarray) -> MovementSpan:
    """The samples at which a movement with speeds (K,) ≥ 0 and a positive peak moves (module docstring)."""
    moving = np.flatnonzero(speed >= MOVING_FRACTION * speed.max())
    return MovementSpan(int(moving[0]), min(int(moving[-1]) + 1, len(speed) - 1))


class TimedPlan(NamedTuple):
    """A plan played at a person's timing (:func:`timed_plan`). Shapes: H steps, nx state entries, n inputs."""

    t: np.ndarray
    """Times of the states (H+1,), s, evenly spaced."""
    mean: np.ndarray
    """Mean states (H+1, nx)."""
    cov: np.ndarray
    """State covariances (H+1, nx, nx)."""
    torque: np.ndarray
    """Commands (H, n)."""


def timed_plan(mean: np.ndarray, cov: np.ndarray, torque: np.ndarray, h: float, n: int,
               timing: ReachTiming | None) -> TimedPlan:
    """A plan (mean (H+1, nx), cov (H+1, nx, nx), torque (H, n); steps of ``h`` s from rest at t = 0; state blocks
    of ``n``: position, velocity, then force-like stages) played at ``timing`` (module docstring). None, or a plan
    that does not move, or a timing without a movement time: the plan as it is, from t = 0."""
    t = h * np.arange(len(mean))
    speed = np.sqrt((mean[:, n:2 * n] ** 2).sum(axis=1))
    if timing is None or not speed.max() > 0 or not timing.movement_time_s > 0:
        return TimedPlan(t, mean, cov, torque)
    span = movement_span(speed)
    pace = timing.movement_time_s / (h * (span.last - span.first))
    scale = np.repeat([1.0, 1.0 / pace] + [pace**-2] * (mean.shape[1] // n - 2), n)
    return TimedPlan(timing.onset_s + pace * (t - h * span.first), mean * scale, cov * np.outer(scale, scale),
                     torque / pace**2)
