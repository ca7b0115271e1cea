"""comanip: predict human reaching with motor-control objectives and plan robot co-manipulation around it.

Haninger & Peternel, "Planning Human-Robot Co-manipulation with Human Motor Control Objectives and
Multi-component Reaching Strategies". See ``comanip.planning.planner`` for the problem statement.
"""

from comanip import presets
from comanip.estimation import OnlineGoalEstimator, estimate_goal, goal_posterior
from comanip.fitting import FitResult, fit_model, fit_movement_times
from comanip.model import ReachingModel
from comanip.multicomponent.transition_model import TransitionModel
from comanip.planning import Plan, Planner, SolverOptions, plan_reach

__version__ = "0.1.0"

__all__ = ["presets", "ReachingModel", "Plan", "Planner", "SolverOptions", "plan_reach", "TransitionModel", "estimate_goal", "goal_posterior", "OnlineGoalEstimator",
           "fit_model", "fit_movement_times", "FitResult"]
