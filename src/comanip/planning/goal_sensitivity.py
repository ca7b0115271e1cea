"""How a converged point-mass plan's torques move with its goal: d tau*/d goal = -∇²f⁻¹ ∂²f/∂tau∂goal by the
implicit function theorem, from the Cholesky factor of the solve's last Newton step and the evaluation at the
plan. A :class:`~comanip.planning.plan.Plan` carries it (``plan.goal_sensitivity``), so a warm solve from the plan
to a moved goal can start from the tangential prediction (:class:`~comanip.planning.starts.start_policy.StartPolicy`)
and a solve depends only on its arguments."""

from __future__ import annotations

import numpy as np

from comanip.optim import CholeskyFactor


class GoalSensitivity:
    """d tau*/d goal (H·n, d) of one plan, computed on first use, not after every solve.

    Args:
        curvature: the exact Newton terms the plan was solved with (their ``goal_cross_derivative``).
        factor: the Cholesky factor of the solve's last Newton step; data: the evaluation at the plan.
        single_thread: a context in which the BLAS runs on one thread (the planner's).
    """

    def __init__(self, curvature, factor: CholeskyFactor, data, single_thread):
        self._curvature, self._factor, self._data, self._single_thread = curvature, factor, data, single_thread
        self._matrix: np.ndarray | None = None

    def is_for(self, curvature) -> bool:
        """Whether the sensitivity was computed with these Newton terms (the same planner's problem)."""
        return curvature is not None and curvature is self._curvature

    def matrix(self) -> np.ndarray:
        """d tau*/d goal (H·n, d)."""
        if self._matrix is None:
            with self._single_thread:
                self._matrix = -self._factor.solve(self._curvature.goal_cross_derivative(self._data))
            self._factor = self._data = None
        return self._matrix

    def __reduce__(self):
        # a plan sent to another process does not carry its solver's terms: there it predicts nothing
        return (_unpickled, ())


def _unpickled():
    return None
