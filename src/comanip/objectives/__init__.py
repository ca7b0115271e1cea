"""Objectives: expected reward of hitting the goal, its discounting over time, and effort."""

from comanip.objectives.discounting import DISCOUNT_FORMS, discount_weights
from comanip.objectives.reach_objective import reach_objective, velocity_cost
from comanip.objectives.reward import GOAL_COVARIANCE_FORMS, REWARD_FORMS, GoalReward, expected_reward, goal_covariance

__all__ = [
    "DISCOUNT_FORMS",
    "GOAL_COVARIANCE_FORMS",
    "REWARD_FORMS",
    "GoalReward",
    "discount_weights",
    "expected_reward",
    "goal_covariance",
    "reach_objective",
    "velocity_cost",
]
