"""The planning problem and its solver, the result object, and where each solve starts (:mod:`comanip.planning.starts`).
A solve's parameters are a :class:`ReachParameters`."""

from comanip.planning.plan import Plan
from comanip.planning.planner import Planner, plan_reach
from comanip.planning.solver_options import SolverOptions
from comanip.planning.reach_parameters import ReachParameters

__all__ = ["Plan", "Planner", "ReachParameters", "SolverOptions", "plan_reach"]
