"""How a solver ends: the outcomes every solver in :mod:`comanip.optim` reports. The layers that build on the
solvers define the outcomes of their own problems beside them, as ``str`` enums too."""

from __future__ import annotations

from enum import StrEnum


class Status(StrEnum):
    """How a solve ended. A ``str``: ``result.status == "solved"`` holds, and it prints and serialises as
    its value."""

    SOLVED = "solved"
    """Converged to the tolerance."""
    SOLVED_ACCEPTABLE = "solved_acceptable"
    """Converged to an acceptable level (an approximate Hessian's linear convergence stalled short of the
    tolerance with the solution settled)."""
    MAX_ITERATIONS = "max_iterations"
    """The iteration limit was reached; the best point so far is returned."""
    MAX_WALL_TIME = "max_wall_time"
    """The wall-time budget ran out; the best point so far is returned."""
    CONSTRAINTS_VIOLATED = "constraints_violated"
    """The constraints could not be met."""
    NOT_A_MINIMUM = "not_a_minimum"
    """The first-order conditions hold at a point that is not a strict minimum."""
    FAILED = "failed"
    """No usable point (non-finite values, a singular system, no descent)."""


CONVERGED = frozenset({Status.SOLVED, Status.SOLVED_ACCEPTABLE})
"""The solver outcomes that count as success."""

BUDGET_SPENT = frozenset({Status.MAX_ITERATIONS, Status.MAX_WALL_TIME})
"""The solver outcomes of a solve its iteration or time budget stopped."""
