"""The numerical pieces every solver in comanip shares: one status vocabulary (:class:`Status`), one result
type (:class:`SolverResult`), one regularised factorisation (:func:`shifted_cholesky`) and one Armijo line
search on an l1 merit (:func:`backtrack`).

The planner's active-set Newton method (:mod:`comanip.optim.active_set_newton`) and the goal estimator's Newton
iteration on the regret's first-order conditions (:mod:`comanip.estimation.regret_newton`) are built from
them. Names of solver quantities follow ``docs/notation.md`` (``hessian``, ``shift``, ``merit_weight``,
``working``, ``multipliers``), so they never collide with the paper's H, W, mu and nu.
"""

from comanip.optim.factorisation import cholesky_solve, decade_shifts, growing_shifts, shifted_cholesky
from comanip.optim.line_search import ARMIJO, backtrack
from comanip.optim.result import LocalModel, SolverResult
from comanip.optim.status import CONVERGED, Status

__all__ = ["ARMIJO", "CONVERGED", "LocalModel", "SolverResult", "Status", "backtrack", "cholesky_solve", "decade_shifts", "growing_shifts", "shifted_cholesky"]
