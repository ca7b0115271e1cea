"""A goal a robot can follow: the estimate's goal with its jumps averaged out, its drift passed on at once.

An explanation's goal is recomputed from the evidence at every update, and some move in steps: the people
model's regression trees (:mod:`comanip.estimation.people.people_model`) change their answer as the movement's numbers
cross a split, so its goal steps by a tenth of the reach or more between two samples. A robot that follows the
goal would jerk with it. :class:`GoalSmoother` passes the goal's motion on at once up to a rate of
``free_rate`` reach distances per second, and averages out the excess with time constant ``time_constant``:
over an update of dt seconds, with D the reach's distance so far (the larger of the smoothed goal's and the
hand's distance from the start) and s the step from the smoothed goal to the new one,

    step = s                                                    if |s| ≤ f
         = s / |s| · (f + (1 - exp(-dt / time_constant)) (|s| - f))  otherwise,   f = free_rate · dt · D,

so a goal drifting smoothly as evidence accrues is not delayed, and a step is spread over a few time constants.
The smoothed goal's covariance is the unsmoothed one plus the outer product of their difference: how far the
smoothed goal may lie from where the evidence says. An estimate that does not follow the hand (the prior, before
the hand leaves its start) resets the smoother: the first goal after it is taken as it is.

Shapes: d task dimensions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_positive


@dataclass(frozen=True)
class GoalSmoothing:
    """How :class:`GoalSmoother` smooths a goal (module docstring)."""

    free_rate: float = 3.75
    """The goal's motion up to this many reach distances per second (1/s) passes on at once."""
    time_constant: float = 0.016
    """The excess is averaged with this time constant (s)."""

    def __post_init__(self):
        as_positive("goal smoothing free_rate", self.free_rate, "reach distances per second, 1/s")
        as_positive("goal smoothing time_constant", self.time_constant, "s")


class GoalSmoother:
    """The smoothed goal of one reach's successive estimates (module docstring)."""

    def __init__(self, smoothing: GoalSmoothing, start_position: np.ndarray):
        self.smoothing = smoothing
        self.start_position = np.asarray(start_position, dtype=float)
        self.reset()

    def reset(self) -> None:
        """Forget the previous goal: the next one is taken as it is."""
        self._goal: np.ndarray | None = None
        self._time = -math.inf

    def smooth(self, time_s: float, goal: np.ndarray, covariance: np.ndarray,
               hand_position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(smoothed goal (d,) m, its covariance (d, d) m²) after the estimate ``goal`` (d,) m with ``covariance``
        (d, d) m² at ``time_s`` (s), the hand at ``hand_position`` (d,) m."""
        goal = np.asarray(goal, dtype=float)
        previous, dt = self._goal, time_s - self._time
        if previous is None or not dt > 0:
            smoothed = goal.copy()
        else:
            step = goal - previous
            size = float(np.linalg.norm(step))
            distance = max(float(np.linalg.norm(previous - self.start_position)),
                           float(np.linalg.norm(hand_position - self.start_position)))
            free = self.smoothing.free_rate * dt * distance
            if size > free:
                step = step * (free + (1.0 - math.exp(-dt / self.smoothing.time_constant)) * (size - free)) / size
            smoothed = previous + step
        self._goal, self._time = smoothed, time_s
        offset = smoothed - goal
        return smoothed, covariance + np.outer(offset, offset)
