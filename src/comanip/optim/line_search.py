"""One line search: backtracking on a merit function until it decreases by a fraction of the predicted
decrease (Armijo's condition, Nocedal & Wright 2006, sec. 3.1), as both Newton methods use it on an l1
merit m(alpha) = f + merit_weight·|c|_1 along a step."""

from __future__ import annotations

from typing import Callable, TypeVar

T = TypeVar("T")

ARMIJO = 1e-4
"""Fraction of the linearly predicted decrease of the merit a step must achieve."""


def backtrack(attempt: Callable[[float, float], T | None], merit: float, slope: float, *,
              max_trials: int) -> tuple[float, T | None]:
    """The first step length alpha in 1, 1/2, 1/4, ... (at most ``max_trials``) that ``attempt`` accepts.

    Args:
        attempt: (alpha, bound) -> the accepted trial, or None; it accepts when the merit at the trial
            point is at most ``bound`` = merit + ARMIJO·alpha·slope (and whatever else the caller requires).
        merit: the merit at alpha = 0.
        slope: its directional derivative along the step (< 0 for a descent step).
        max_trials: step lengths tried.

    Returns:
        (alpha, trial) for the accepted trial; (the next, untried alpha, None) when none was accepted.
    """
    alpha = 1.0
    for _ in range(max_trials):
        accepted = attempt(alpha, merit + ARMIJO * alpha * slope)
        if accepted is not None:
            return alpha, accepted
        alpha *= 0.5
    return alpha, None
