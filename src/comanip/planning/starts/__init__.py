"""Where a solve starts (:class:`StartPolicy`, one strategy per kind of body: :class:`PointMassStarts`,
:class:`ArmStarts`): minimum-jerk guesses, retargeted and predicted warm starts, and the reach libraries of point
masses and arms."""

from comanip.planning.starts.arm_starts import ArmStarts
from comanip.planning.starts.point_mass_starts import PointMassStarts
from comanip.planning.starts.start_policy import StartPolicy

__all__ = ["ArmStarts", "PointMassStarts", "StartPolicy"]
