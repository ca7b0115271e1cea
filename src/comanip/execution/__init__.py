"""Executing plans on the noisy arm: open loop (sampled motor noise) and closed loop (receding horizon), the
latter from the actual state or from a Kalman estimate made from noisy, delayed feedback."""

from comanip.execution.kalman_filter import DelayedKalmanFilter
from comanip.execution.delayed_observation import Observation
from comanip.execution.receding_horizon import Execution, execute_receding_horizon, executed_cost

__all__ = ["DelayedKalmanFilter", "Execution", "Observation", "execute_receding_horizon", "executed_cost"]
