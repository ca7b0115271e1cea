"""(e) comanip's continuous estimate: the robot feeds every observation of the handle, one every
``update_interval`` from the start of the reach, to an :class:`comanip.estimation.OnlineGoalEstimator`
(warm-started from its previous estimate) and, from t_o on, leads along the latest estimate's predicted
reach, replanned at every update."""

from __future__ import annotations

import numpy as np

from comanip.estimation import OnlineGoalEstimator, OnlineOptions
from comanip.estimation.online_estimator import CORRECTING_PERSON
from comanip.simulation.policies.protocol import PolicyContext, Prediction
from comanip.simulation.rest_trajectory import RestTrajectory


class ContinuousPolicy:
    """The online MAP goal and its predicted reach, revised with each observation.

    prior_std: the prior goal's standard deviation (m), as :class:`OnlineGoalEstimator` takes it (None: its
    weak default). options: the estimator's :class:`OnlineOptions`; default: a person who corrects deviations from
    their plan (``CORRECTING_PERSON``: :mod:`comanip.estimation.corrected_deviation`), as the
    simulated person does by replanning.
    """

    name = "continuous"

    def __init__(self, context: PolicyContext, prior_std=None, options: OnlineOptions | None = None):
        self.context = context
        self.update_interval = context.update_interval
        self.estimator = OnlineGoalEstimator(context.model, context.start, prior_goal=context.prior_goal,
                                             prior_std=prior_std, width=context.width, options=options or CORRECTING_PERSON)
        self._next_observation = context.update_interval

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray) -> None:
        if t >= self._next_observation - 1e-9:
            self.estimator.update(t, position, velocity)
            self._next_observation += self.update_interval

    def predict(self, t: float) -> Prediction | None:
        """The latest estimate's goal and predicted reach; None (do not lead yet) before the first observation,
        e.g. when update_interval is longer than t_o."""
        c, estimate = self.context, self.estimator.latest
        if estimate is None:
            return None
        return Prediction(np.array(estimate.goal), RestTrajectory.from_plan(estimate, 0.0, c.dt, c.duration), estimate)
