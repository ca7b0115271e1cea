"""The planning problem and its solver, the result object, and where each solve starts (:mod:`comanip.planning.starts`).
A solve's parameters are a :class:`ReachParameters`; a control loop replans on a per-cycle budget with a
:class:`Replanner` (:mod:`comanip.planning.replanner`)."""

from comanip.planning.plan import Plan
from comanip.planning.planner import Planner, plan_reach
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.replanner import Replan, Replanner, shifted_torques
from comanip.planning.solver_options import SolverOptions

__all__ = ["Plan", "Planner", "ReachParameters", "Replan", "Replanner", "SolverOptions", "plan_reach", "shifted_torques"]
