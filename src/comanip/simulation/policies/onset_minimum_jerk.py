"""(h) The height on a fixed clock: from the onset of the person's reach (t = 0) the robot leads the height along a
rest-to-rest minimum-jerk motion of a fixed duration T to the placing height h,

    z(t) = z_0 + (h - z_0) sigma(t / T),   sigma(s) = 10 s³ - 15 s⁴ + 6 s⁵ (s clipped to [0, 1]),

T the movement time of the model's reach to the prior goal (:attr:`PolicyContext.expected_movement_time`): what a
lab robot that knows the height and a typical reach's duration, but not this person's, does. Predicted once, at t_o
(the motion is already under way then); its goal is the prior goal at the height."""

from __future__ import annotations

import numpy as np

from comanip.planning.starts.initial_guess import minimum_jerk
from comanip.simulation.policies.protocol import PolicyContext, Prediction


class OnsetMinimumJerkPolicy:
    """Leads the height along a minimum-jerk motion of fixed duration from the onset (module docstring).

    onset: when the motion starts (s from the start of the reach; 0: at the onset). duration: T (s); None: the
    model's movement time to the prior goal."""

    name = "onset-minimum-jerk"
    leads_height = True
    update_interval = None

    def __init__(self, context: PolicyContext, onset: float = 0.0, duration: float | None = None):
        self.context = context
        self.onset = float(onset)
        self.duration = context.expected_movement_time if duration is None else float(duration)

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        pass

    def predict(self, t: float) -> Prediction:
        c = self.context
        start = np.array(c.start[:3], dtype=float)
        goal = np.array(c.prior_goal, dtype=float)
        if c.goal_height is not None:
            goal[2] = c.goal_height
        end = start.copy()
        end[2] = goal[2]
        position, velocity, _ = minimum_jerk(start, np.zeros(3), end, self.duration, np.maximum(c.rest_times(t) - self.onset, 0.0))
        return Prediction(goal, c.rest_from(t, position, velocity))
