"""The numerical pieces every solver in comanip shares: one Newton iteration (:func:`newton_iterate`, over a
:class:`NewtonMethod`'s hooks), one vocabulary of solver outcomes (:class:`Status`), one evaluation type
(:class:`Evaluation`), one result type (:class:`SolverResult`) and how far a budgeted solve got (:class:`Progress`), one regularised factorisation
(:func:`shifted_cholesky`, giving a :class:`CholeskyFactor`) and one Armijo line search (:func:`backtrack`).

The active-set Newton method (:func:`newton_minimize`, :mod:`comanip.optim.active_set_newton`) is built from them, and
so is every solver of the layers above. Names of solver quantities follow ``docs/notation.md`` (``hessian``,
``shift``, ``merit_weight``, ``working``, ``multipliers``), so they never collide with the paper's H, W, mu and nu.
"""

from comanip.optim.evaluation import Evaluation
from comanip.optim.factorisation import CholeskyFactor, decade_shifts, growing_shifts, shifted_cholesky
from comanip.optim.line_search import ARMIJO, Backtracked, backtrack
from comanip.optim.result import LocalModel, SolverResult
from comanip.optim.status import BUDGET_SPENT, CONVERGED, Status
from comanip.optim.newton_loop import NewtonMethod, NewtonSolve, Stop, newton_iterate
from comanip.optim.active_set_newton import newton_minimize, newton_solve
from comanip.optim.progress import Progress, contraction, progress_of

__all__ = ["ARMIJO", "BUDGET_SPENT", "Backtracked", "CONVERGED", "CholeskyFactor", "Evaluation", "LocalModel", "NewtonMethod", "NewtonSolve", "Progress", "SolverResult", "Status", "Stop", "backtrack", "contraction",
           "decade_shifts", "growing_shifts", "newton_iterate", "newton_minimize", "newton_solve", "progress_of",
           "shifted_cholesky"]
