"""Where a solve starts (:class:`StartPolicy`): minimum-jerk guesses, retargeted and predicted warm starts, and
the reach libraries of point masses and arms."""

from comanip.planning.starts.start_policy import StartPolicy

__all__ = ["StartPolicy"]
