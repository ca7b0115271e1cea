"""The result of a solve, in the spirit of scipy's ``OptimizeResult``."""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from typing import Generic, TypeVar

from comanip.optim.factorisation import CholeskyFactor
from comanip.optim.status import CONVERGED

X = TypeVar("X")
D = TypeVar("D")
M = TypeVar("M")


@dataclass(frozen=True)
class LocalModel(Generic[D]):
    """What the active-set Newton method knows of the objective at its result, D the type of the caller's
    evaluation data."""

    factor: CholeskyFactor | None
    """The Cholesky factor of the (regularised, corrected) Hessian of the last step taken; None if no step was
    taken or its matrix had secant updates since it was factored."""
    data: D
    """The evaluation's data at the result."""


@dataclass
class SolverResult(Generic[X, M]):
    """Where a solver stopped and why; never an exception for an unconverged solve. X is the point's type, M the
    type of what the solver knows of the objective at it."""

    x: X
    """The best point found (an array (N,), or the solver's own point type)."""
    fun: float
    """The objective there."""
    status: StrEnum
    """A :class:`~comanip.optim.status.Status`, or a status of the layer whose hooks stopped the solve (a ``str`` enum too)."""
    message: str
    """The status in words."""
    nit: int
    """Iterations, as the solver counts them (Hessian evaluations, linearisations)."""
    optimality: float
    """First-order optimality at x: max |gradient of the Lagrangian|, or max |F| for a root finder; NaN where the
    gradient at x was left unevaluated (:meth:`~comanip.optim.NewtonSolve.advance` with ``gradient_at_end=False``)."""
    violation: float = 0.0
    """Largest constraint violation at x (units of the constraints)."""
    local_model: M | None = None
    """What the solver knows of the objective at and around x, for callers that build on it (the active-set Newton
    method: a :class:`LocalModel`); None when it has nothing."""
    start_optimality: float = math.nan
    """``optimality`` at the point the solve started from, where the solver knows it (NaN otherwise): with
    ``optimality`` it says whether the iterations contracted (:func:`~comanip.optim.progress.progress_of`)."""

    @property
    def success(self) -> bool:
        """True when the solver converged (to its tolerance or an acceptable level)."""
        return self.status in CONVERGED
