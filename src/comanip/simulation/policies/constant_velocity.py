"""(b) Constant-velocity extrapolation of the hand: the hand keeps its current velocity v for the rest of
the reach the robot expects, so from x at time t the goal is x + v·tau, tau = max(MT_prior - t, 0), where
MT_prior is the movement time of the model's reach to the prior goal; the rest motion is that straight
line at speed |v|, held at its end. Re-predicted every update_interval."""

from __future__ import annotations

import numpy as np

from comanip.simulation.policies.protocol import PolicyContext, Prediction


def constant_velocity_goal(position, velocity, time_to_go: float) -> np.ndarray:
    """x + v·tau (d,), m: where a hand at position (d,) m moving at velocity (d,) m/s is after time_to_go (s)."""
    return np.asarray(position, dtype=float) + max(float(time_to_go), 0.0) * np.asarray(velocity, dtype=float)


class ConstantVelocityPolicy:
    """Extrapolates the latest observed hand state over the expected remaining time."""

    name = "constant-velocity"
    leads_height = True

    def __init__(self, context: PolicyContext):
        self.context = context
        self.update_interval = context.update_interval
        self.position = self.velocity = None

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        self.position, self.velocity = np.array(position, dtype=float), np.array(velocity, dtype=float)

    def predict(self, t: float) -> Prediction:
        c = self.context
        time_to_go = max(c.expected_movement_time - t, 0.0)
        times = c.rest_times(t) - t
        moving = (times <= time_to_go)[:, None]
        position = self.position + np.minimum(times, time_to_go)[:, None] * self.velocity
        velocity = np.where(moving, self.velocity, 0.0)
        return Prediction(constant_velocity_goal(self.position, self.velocity, time_to_go), c.rest_from(t, position, velocity))
