"""(d) The paper's one-shot estimate (paper V-C, VI-A): at t_o the robot estimates the goal and the whole
reach once (:class:`comanip.estimation.GoalEstimator`) from the start s_0 and the state s_o it recorded at
the model's step n_o = floor(t_o / h) (0.165 s for t_o = 0.2 s and h = 0.055 s), and never revises it.
Handing the estimator the state at t_o itself, 35 ms later than the step it stands for, would make the
person look faster than they are and the estimate overshoot the goal by tens of centimetres."""

from __future__ import annotations

import numpy as np

from comanip.estimation.goal_prior import PAPER_PRIOR
from comanip.simulation.policies.protocol import PolicyContext, Prediction
from comanip.simulation.rest_trajectory import RestTrajectory


class OneShotPolicy:
    """One estimate at t_o from the state at step n_o, then the estimated reach as the rest motion."""

    name = "one-shot"
    leads_height = True
    update_interval = None

    def __init__(self, context: PolicyContext):
        self.context = context
        h = context.model.h
        self.observation_step = int(np.floor(context.observation_time / h + 1e-9))
        self.observation_time = self.observation_step * h
        """When s_o is taken (s): the model's step n_o."""
        self.observed: np.ndarray | None = None

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        if self.observed is None and t >= self.observation_time - 0.5 * self.context.dt:
            self.observed = np.r_[position, velocity]

    def predict(self, t: float) -> Prediction:
        c = self.context
        # the paper's estimate: its prior weighted by W from the width (paper VI-A)
        estimate = c.estimator.estimate(c.start, self.observed, self.observation_time, c.prior_goal, c.width,
                                        prior_std=PAPER_PRIOR, warm_start=c.warm_start)
        return Prediction(np.array(estimate.goal), RestTrajectory.from_plan(estimate, 0.0, c.dt, c.duration), estimate)
