"""Robot control laws, independent of any simulator: NumPy arrays in, joint torques out."""

from comanip.control.impedance import CartesianImpedanceController, ImpedanceGains, RobotState

__all__ = ["CartesianImpedanceController", "ImpedanceGains", "RobotState"]
