"""The status vocabulary of every solve: plans, goal estimates and goal posteriors."""

from __future__ import annotations

from enum import StrEnum


class Status(StrEnum):
    """How a solve ended. A ``str``: ``plan.status == "solved"`` holds, and it prints and serialises as
    its value."""

    SOLVED = "solved"
    """Converged to the tolerance."""
    SOLVED_ACCEPTABLE = "solved_acceptable"
    """Converged to an acceptable level (an approximate Hessian's linear convergence stalled short of the
    tolerance with the solution settled)."""
    GOAL_NOT_REACHED = "goal_not_reached"
    """A plan whose solver converged but whose mean end effector ends farther than the goal width from the goal."""
    MAX_ITERATIONS = "max_iterations"
    """The iteration limit was reached; the best point so far is returned."""
    MAX_WALL_TIME = "max_wall_time"
    """The wall-time budget ran out; the best point so far is returned."""
    CONSTRAINTS_VIOLATED = "constraints_violated"
    """The joint limits could not be met."""
    NOT_A_MINIMUM = "not_a_minimum"
    """A goal estimate met its first-order conditions at a point that is not a strict minimum."""
    UNREACHABLE = "unreachable"
    """The goal is out of the arm's reach; nothing was solved."""
    UNINFORMATIVE = "uninformative"
    """The observation says nothing about the goal (it is the start itself)."""
    PLANS_NOT_CONVERGED = "plans_not_converged"
    """A goal posterior some of whose candidates' plans did not converge."""
    PEOPLE_MODEL = "people_model"
    """A goal estimate from the model fitted to recorded people (:mod:`comanip.estimation.people_model`): the
    reaching model at its own pace does not explain the observed hand."""
    FAILED = "failed"
    """No usable point (non-finite values, a singular system, no descent)."""


CONVERGED = frozenset({Status.SOLVED, Status.SOLVED_ACCEPTABLE, Status.PEOPLE_MODEL})
"""The statuses that count as success."""
