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


PRIOR_STD = 0.25
"""The robot's prior goal's standard deviation per axis (m): things are placed within about ±0.5 m of the table
centre (the scenario's goals lie 0.07–0.38 m from it). With the estimator's weak default (10 m) the first
estimates, from 0.2 s of the reach, were farther off than the prior alone (medians 0.18–0.40 m over 20 trials
per goal); with this prior 0.06–0.19 m, and the final error within 0.2 mm of before (README, policy comparison)."""


class ContinuousPolicy:
    """The online MAP goal and its predicted reach, revised with each observation.

    prior_std: the prior goal's standard deviation (m), as :class:`OnlineGoalEstimator` takes it (None: the
    estimator's weak default; default :data:`PRIOR_STD`). options: the estimator's :class:`OnlineOptions`; default: a person who corrects deviations from
    their plan (``CORRECTING_PERSON``: :mod:`comanip.estimation.corrected_deviation`), as the
    simulated person does by replanning.
    """

    name = "continuous"

    def __init__(self, context: PolicyContext, prior_std=PRIOR_STD, options: OnlineOptions | None = None):
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
