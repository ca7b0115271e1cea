"""The planning problem and its solver, the result object, and initial guesses."""

from comanip.planning.plan import Plan
from comanip.planning.planner import Planner, SolverOptions, plan_reach

__all__ = ["Plan", "Planner", "SolverOptions", "plan_reach"]
