"""A stand-in with the online estimator's interface (``update(time_s, position, velocity)`` returning an
estimate with ``goal`` and ``goal_covariance``), built on today's :class:`~comanip.estimation.GoalEstimator`:
each update estimates the goal from the start and the newest observation alone, warm-started from the
previous estimate. It lives only until ``comanip.estimation.OnlineGoalEstimator`` (which uses every
observation and calibrates its covariance) is merged; :func:`comanip.ros.node.reach_estimator` then calls that
instead and this file goes.

Its ``goal_covariance`` is the model's goal covariance W (w² I for the presets): the spread the planner assumes
around a goal, not a posterior.
"""

from __future__ import annotations

import numpy as np

from comanip.estimation import GoalEstimate, GoalEstimator
from comanip.objectives.reward import goal_covariance


class InterimGoalEstimator:
    """Goal estimates of one reach of a point mass (state [x; xdot], d = n) from its start (2n,)."""

    def __init__(self, estimator: GoalEstimator, start, *, prior_goal=None, width: float | None = None,
                 max_wall_time: float | None = None):
        self._estimator = estimator
        self._start = np.asarray(start, dtype=float)
        self._prior_goal = prior_goal
        self._width = width
        self._max_wall_time = max_wall_time
        model = estimator.model
        self._covariance = goal_covariance(model.width if width is None else width, model.d, model.goal_covariance, model.effective_k)
        self.latest: GoalEstimate | None = None

    def _warm_start(self) -> GoalEstimate | None:
        """The previous estimate if its goal is finite (a solve cut short by its budget still starts the next one
        closer than a cold search)."""
        latest = self.latest
        return latest if latest is not None and np.all(np.isfinite(latest.goal)) else None

    def update(self, time_s: float, position, velocity) -> GoalEstimate:
        """The estimate after observing the hand at ``position`` (d,) m with ``velocity`` (d,) m/s, ``time_s``
        after the start; ValueError for bad input, never for a failed solve (see ``success``)."""
        observed = np.r_[np.asarray(position, dtype=float), np.asarray(velocity, dtype=float)]
        estimate = self._estimator.estimate(self._start, observed, time_s, self._prior_goal, self._width,
                                            warm_start=self._warm_start(),
                                            max_wall_time=self._max_wall_time)
        estimate.goal_covariance = self._covariance
        self.latest = estimate
        return estimate
