"""What a solver's objective returns at a point."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Generic, TypeVar

import numpy as np

D = TypeVar("D")


@dataclass(frozen=True, slots=True)
class Evaluation(Generic[D]):
    """f at a point x (N,), its gradient, and the caller's data there (D: what the Hessian and the constraints
    read)."""

    f: float
    gradient: np.ndarray | None
    """∇f (N,); None for a value-only evaluation."""
    data: D
