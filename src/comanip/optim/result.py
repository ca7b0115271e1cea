"""The result of a solve, in the spirit of scipy's ``OptimizeResult``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from comanip.optim.status import CONVERGED, Status

X = TypeVar("X")


@dataclass(frozen=True)
class LocalModel:
    """What the active-set Newton method knows of the objective at its result: the Cholesky factor of the
    (regularised, corrected) Hessian of the last step taken (as :func:`~comanip.optim.shifted_cholesky` gives it;
    None if no step was taken or its matrix had secant updates since it was factored) and the evaluation's data
    at the result."""

    factor: tuple | None
    data: Any


@dataclass
class SolverResult(Generic[X]):
    """Where a solver stopped and why; never an exception for an unconverged solve."""

    x: X
    """The best point found: an array (N,) for the planner, a RegretPoint for the goal estimate."""
    fun: float
    """The objective there (normalised J for the planner, the normalised regret for the goal estimate)."""
    status: Status
    message: str
    """The status in words."""
    nit: int
    """Iterations: Hessian evaluations (planner) or linearisations (goal estimate)."""
    optimality: float
    """First-order optimality at x: max |gradient of the Lagrangian| (planner) or max |F| (goal estimate)."""
    violation: float = 0.0
    """Largest constraint violation at x (units of the constraints)."""
    local_model: Any = None
    """What the solver knows of the objective at and around x, for callers that build on it (the active-set Newton
    method: a :class:`LocalModel`; the online estimator's MAP: its terms); None when it has nothing."""

    @property
    def success(self) -> bool:
        """True when the solver converged (to its tolerance or an acceptable level)."""
        return self.status in CONVERGED
