"""(f) The forecast of the hand: the continuous policy's online estimate (:mod:`continuous`), but the robot leads
along the estimate's forecast of the rest of the reach (``estimate.forecast``: the model's continuation from the
hand's state, and its covariance) and gives way.

The forecast starts at the handle, and on the axes the robot leads (z) the handle moves as the robot does, so a
rest motion that follows the forecast's z follows the robot's own motion. The lead therefore reads the forecast
only on the axes the person leads (x–y) and carries the height along with them: with x_0 the handle at the start,
x_f(t) the forecast and g the estimate's goal, the rest's z is

    z(t) = z_0 + (h - z_0) min(1, |x_f,xy(t) - x_0,xy| / D),   D² = |g_xy - x_0,xy|² + tr P_xy,

h the placing height when the scenario knows it (else g_z), P_xy the goal covariance's x–y block: the forecast's
distance covered in x–y over the distance the estimate expects, trusted as far as its covariance says (an
uncertain goal spreads the expected distance, so the lead descends no faster than the estimate is sure of). The
rest's x–y are the forecast's (the robot does not lead them). The robot gives way: its rest goes a share of the
way from the handle to the lead, :data:`LEAD_SHARE` once the person's hand has covered :data:`RAMP_DISTANCE` in x–y
and in proportion to the distance covered before; and it leads only once the estimate explains the hand
(``estimate.success``).
"""

from __future__ import annotations

import numpy as np

from comanip.simulation.policies.continuous import ContinuousPolicy
from comanip.simulation.policies.protocol import Prediction

LEAD_SHARE = 0.3
"""The share of the way from the handle to the lead the robot's rest goes (:attr:`Prediction.lead_share`): its
spring and damper pull with 0.3 of their force. Chosen by the person's RMS force change on person seeds 20–22, not
the results page's (docs/results/policy_comparison.md, "How the forecast policy's constants were chosen")."""

RAMP_DISTANCE = 0.1
"""The person's x–y distance from the start (m) by which the share reaches :data:`LEAD_SHARE`, growing in proportion
to it before: early in a reach the estimate rests on little motion (an estimate that explains a hand barely under
way may put the goal about the hand, confidently), and a full lead to the height would pull the handle down ahead
of the person. Chosen with LEAD_SHARE, on the same seeds."""


def height_along(positions: np.ndarray, start: np.ndarray, goal: np.ndarray, goal_covariance: np.ndarray,
                 height: float, axes=(0, 1)) -> tuple[np.ndarray, np.ndarray]:
    """The lead's progress and height (module docstring) along forecast positions (M, 3) m from the start (3,) m
    to the goal (3,) m with its covariance (3, 3) m², to the height (m); axes: the person's. Returns (progress (M,)
    in [0, 1], z (M,) m)."""
    axes = list(axes)
    chord = goal[axes] - start[axes]
    expected = np.sqrt(float(chord @ chord) + float(np.trace(goal_covariance[np.ix_(axes, axes)])))
    covered = np.linalg.norm(positions[:, axes] - start[axes], axis=1)
    progress = np.clip(covered / max(expected, 1e-9), 0.0, 1.0)
    return progress, start[2] + (height - start[2]) * progress


class ForecastPolicy(ContinuousPolicy):
    """The online estimate's forecast as the lead, read on the person's axes, the robot giving way."""

    name = "forecast"

    def predict(self, t: float) -> Prediction | None:
        """The forecast from time t on as the rest motion (module docstring); None (do not lead, or keep the last
        lead) while the estimate does not explain the hand."""
        c, estimate = self.context, self.estimator.latest
        if estimate is None or not estimate.success:
            return None
        goal = np.array(estimate.goal, dtype=float)
        times = c.rest_times(t)
        forecast = estimate.forecast.at(times)
        position, velocity = forecast.position.copy(), forecast.velocity.copy()
        height = goal[2] if c.goal_height is None else c.goal_height
        person_axes = [a for a in range(3) if a not in self.settings.options.led_axes]
        _, position[:, 2] = height_along(position, c.start[:3], goal, np.asarray(estimate.goal_covariance), height,
                                         person_axes)
        velocity[:, 2] = np.gradient(position[:, 2], c.dt)
        covered = float(np.linalg.norm(position[0, person_axes] - c.start[person_axes]))
        share = LEAD_SHARE * min(1.0, covered / RAMP_DISTANCE)
        return Prediction(goal, c.rest_from(t, position, velocity), estimate, lead_share=share)
