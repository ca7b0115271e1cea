"""How far a solve run on a budget got (:class:`Progress`): converged, converging, or not contracting.

A solver run for a few iterations at a time (the real-time iteration of model-predictive control: one or a few
Newton iterations per control cycle, each from the last cycle's solution) rarely converges within one call. What a
caller needs to know is whether the iterations are closing in on a solution: they contract when the first-order
optimality (max |gradient of the Lagrangian|) at the returned point is below the one at the start point.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from comanip.optim.result import SolverResult
from comanip.optim.status import BUDGET_SPENT, CONVERGED


class Progress(StrEnum):
    """Where a budgeted solve stands. A ``str``, like :class:`~comanip.optim.Status`."""

    CONVERGED = "converged"
    """The solve converged (status 'solved' or 'solved_acceptable')."""
    CONVERGING = "converging"
    """The budget ran out with the optimality lower than at the start: the iterations contract."""
    NOT_CONTRACTING = "not_contracting"
    """Neither: the budget ran out without lowering the optimality (or before any iteration), or the solve stopped
    on a failure; the point returned is the best the solve had."""



def contraction(start_optimality: float, optimality: float) -> float:
    """The optimality at a solve's result over the optimality at its start (dimensionless; < 1: the iterations
    contracted). NaN when either is unknown, 0 when the start was already optimal to the last digit."""
    if not (np.isfinite(start_optimality) and np.isfinite(optimality)):
        return float("nan")
    return optimality / start_optimality if start_optimality > 0 else 0.0


def progress_of(result: SolverResult) -> Progress:
    """The :class:`Progress` of a solve's result (converged by its status; converging when its budget stopped it with
    :func:`contraction` below 1)."""
    if result.status in CONVERGED:
        return Progress.CONVERGED
    if result.status in BUDGET_SPENT and contraction(result.start_optimality, result.optimality) < 1.0:
        return Progress.CONVERGING
    return Progress.NOT_CONTRACTING
