"""Belief dynamics: how the mean and covariance of the arm's state evolve under motor noise."""

from comanip.belief.noise import NOISE_FORMS, noise_covariance, sample_torque_error
from comanip.belief.propagation import (
    belief_step_function,
    end_effector_belief,
    end_effector_belief_function,
    linearised_step_function,
    propagate_belief,
    sample_trajectories,
)

__all__ = [
    "NOISE_FORMS",
    "noise_covariance",
    "sample_torque_error",
    "belief_step_function",
    "end_effector_belief",
    "end_effector_belief_function",
    "linearised_step_function",
    "propagate_belief",
    "sample_trajectories",
]
