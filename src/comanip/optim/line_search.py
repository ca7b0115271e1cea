"""One line search: backtracking on a merit function until it decreases by a fraction of the predicted
decrease (Armijo's condition, Nocedal & Wright 2006, sec. 3.1), as both Newton methods use it on an l1
merit m(alpha) = f + merit_weight·|c|_1 along a step."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Generic, TypeVar

T = TypeVar("T")

ARMIJO = 1e-4
"""Fraction of the linearly predicted decrease of the merit a step must achieve."""


@dataclass(frozen=True)
class Backtracked(Generic[T]):
    """Where a backtracking line search ended."""

    alpha: float
    """The accepted step length; the next, untried one when none was accepted."""
    accepted: T | None
    """The accepted trial; None when none was."""


def backtrack(attempt: Callable[[float, float], T | None], merit: float, slope: float, *,
              max_trials: int) -> Backtracked[T]:
    """The first step length alpha in 1, 1/2, 1/4, ... (at most ``max_trials``) that ``attempt`` accepts.

    Args:
        attempt: (alpha, bound) -> the accepted trial, or None; it accepts when the merit at the trial
            point is at most ``bound`` = merit + ARMIJO·alpha·slope (and whatever else the caller requires).
        merit: the merit at alpha = 0.
        slope: its directional derivative along the step (< 0 for a descent step).
        max_trials: step lengths tried.

    Returns:
        alpha and the accepted trial; the next, untried alpha and None when none was accepted.
    """
    alpha = 1.0
    for _ in range(max_trials):
        accepted = attempt(alpha, merit + ARMIJO * alpha * slope)
        if accepted is not None:
            return Backtracked(alpha, accepted)
        alpha *= 0.5
    return Backtracked(alpha, None)
