"""Executing plans on the noisy arm: open loop (sampled motor noise) and closed loop (receding horizon)."""

from comanip.execution.receding_horizon import Execution, execute_receding_horizon

__all__ = ["Execution", "execute_receding_horizon"]
