"""(a) Prior goal only: the robot leads along the model's reach from the start to its prior goal and never
looks at the person (its goal error is |g_bar - g| whatever the person does)."""

from __future__ import annotations

import numpy as np

from comanip.simulation.policies.protocol import PolicyContext, Prediction
from comanip.simulation.rest_trajectory import RestTrajectory


class PriorOnlyPolicy:
    """Predicts g_hat = g_bar once, at t_o, with the model's reach to it as the rest motion."""

    name = "prior-only"
    leads_height = True
    update_interval = None

    def __init__(self, context: PolicyContext):
        self.context = context

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        pass

    def predict(self, t: float) -> Prediction:
        c = self.context
        return Prediction(c.prior_goal.copy(), RestTrajectory.from_plan(c.prior_plan, 0.0, c.dt, c.duration), c.prior_plan)
