"""Simple predictors of where a moving hand will stop, the yardsticks of goal estimation.

Each is an online predictor like :class:`comanip.OnlineGoalEstimator`: made for a hand at rest at ``start``
(d,) m, fed observations by ``update(t, position, velocity)`` (s, m, m/s) and answering an
:class:`EndpointPrediction`:

- :class:`CurrentPosition`: the goal is where the hand is now;
- :class:`ConstantVelocity`: where the hand will be ``lead`` seconds on at its current velocity;
- :class:`MinimumJerkFit`: the goal and movement time of the minimum-jerk reach that best fits the movement
  so far (:mod:`comanip.estimation.model_reaches.profile_fit` with the minimum-jerk shape);
- kinematic template matching: :mod:`comanip.estimation.people.template_matching`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_nonnegative, as_vector
from comanip.estimation.model_reaches.profile_fit import detected_onset, fit_profile
from comanip.estimation.model_reaches.reach_profile import ReachProfile

MOVING_SPEED = 0.02
"""Speed (m/s) above which a hand counts as moving (the onset of a reach)."""


@dataclass(frozen=True)
class EndpointPrediction:
    """A predicted endpoint: ``goal`` (d,) m and, where the predictor has one, its ``covariance`` (d, d) m² and
    when the hand gets there, ``end_time`` (s, on the observations' clock)."""

    goal: np.ndarray
    covariance: np.ndarray | None = None
    end_time: float | None = None


class PrefixPredictor:
    """An online endpoint predictor that keeps every observation and predicts from the whole prefix.

    Args:
        start: the hand's rest position before the reach (d,), m.
    """

    name = "prefix"

    def __init__(self, start):
        self.start = as_vector("start", start, np.size(start), "hand position, m")
        self._t: list[float] = []
        self._position: list[np.ndarray] = []
        self._velocity: list[np.ndarray] = []

    def update(self, time_s: float, position, velocity) -> EndpointPrediction:
        """Add an observation (time s, position (d,) m, velocity (d,) m/s) and predict the endpoint."""
        d = self.start.size
        self._t.append(float(time_s))
        self._position.append(as_vector("position", position, d, "hand position, m"))
        self._velocity.append(as_vector("velocity", velocity, d, "hand velocity, m/s"))
        return self.predict(np.asarray(self._t), np.asarray(self._position), np.asarray(self._velocity))

    def predict(self, t: np.ndarray, position: np.ndarray, velocity: np.ndarray) -> EndpointPrediction:
        """The endpoint from the prefix: times (K,) s, positions (K, d) m, velocities (K, d) m/s."""
        raise NotImplementedError


class CurrentPosition(PrefixPredictor):
    """The goal is the hand's current position."""

    name = "current position"

    def predict(self, t, position, velocity):
        return EndpointPrediction(position[-1].copy())


class ConstantVelocity(PrefixPredictor):
    """The hand's position ``lead`` seconds on at its current velocity.

    Args:
        start: rest position (d,), m.
        lead: how far ahead (s).
    """

    name = "constant velocity"

    def __init__(self, start, lead: float = 0.05):
        super().__init__(start)
        self.lead = as_nonnegative("lead", lead, "s")

    def predict(self, t, position, velocity):
        return EndpointPrediction(position[-1] + self.lead * velocity[-1])


class MinimumJerkFit(PrefixPredictor):
    """The endpoint of the minimum-jerk reach, its duration and onset free, that best fits the prefix."""

    name = "minimum jerk"
    _PROFILE = ReachProfile.minimum_jerk()

    def predict(self, t, position, velocity):
        onset = detected_onset(t, np.linalg.norm(velocity, axis=1), MOVING_SPEED)
        if onset is None:
            return EndpointPrediction(position[-1].copy())
        fit = fit_profile(t, position, velocity, self.start, self._PROFILE, onset)
        return EndpointPrediction(fit.goal)
