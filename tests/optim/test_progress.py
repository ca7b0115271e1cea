"""How far a budgeted solve got (comanip.optim.progress) on problems whose answer is known: a quadratic with its own
Hessian (one Newton step converges), a smooth convex problem (a step from far contracts), and a quadratic given a
wrong Hessian, built so that the step the line search accepts raises the gradient (it does not contract)."""

import numpy as np
import pytest

from comanip.optim import Evaluation, Progress, SolverResult, Status, contraction, newton_solve, progress_of

UNBOUNDED = (np.full(2, -np.inf), np.full(2, np.inf))


def quadratic(curvature: np.ndarray):
    """f = ½ xᵀ A x with A = diag(curvature)."""
    return lambda x: Evaluation(0.5 * float(x @ (curvature * x)), curvature * x, None)


def test_a_solve_from_its_optimum_is_converged():
    result = newton_solve(quadratic(np.array([1.0, 100.0])), lambda data: np.diag([1.0, 100.0]), np.zeros(2),
                          *UNBOUNDED, tolerance=1e-10).advance(1)
    assert progress_of(result) is Progress.CONVERGED


def test_one_step_of_a_smooth_convex_problem_contracts():
    # f = Σ log cosh(x): Newton's step from |x| ≤ 0.5 lands within 0.09 of 0, where it converges
    def evaluate(x):
        return Evaluation(float(np.sum(np.log(np.cosh(x)))), np.tanh(x), x)

    result = newton_solve(evaluate, lambda x: np.diag(1 / np.cosh(x) ** 2), np.array([0.5, -0.3]), *UNBOUNDED,
                          tolerance=1e-12).advance(1)
    assert result.status == Status.MAX_ITERATIONS
    assert result.start_optimality == pytest.approx(np.tanh(0.5))
    assert result.optimality == pytest.approx(np.abs(np.tanh(result.x)).max())
    assert contraction(result.start_optimality, result.optimality) < 0.5
    assert progress_of(result) is Progress.CONVERGING


def test_a_wrong_hessian_that_raises_the_gradient_does_not_contract():
    # f = ½ (x₁² + 100 x₂²) given the identity as its Hessian: from (1, 0.001) the full step (-1, -0.1)·1 passes
    # Armijo's test (f drops from 0.50005 to 0.49) but lands where the gradient is (0, -9.9), ten times the start's
    result = newton_solve(quadratic(np.array([1.0, 100.0])), lambda data: np.eye(2), np.array([1.0, 0.001]),
                          *UNBOUNDED, tolerance=1e-10).advance(1)
    assert result.fun < 0.50005 and result.optimality == pytest.approx(9.9)
    assert progress_of(result) is Progress.NOT_CONTRACTING


def test_a_failed_or_unmeasured_solve_is_not_contracting():
    failed = SolverResult(np.zeros(2), 0.0, Status.FAILED, "no descent", 3, 0.1, start_optimality=1.0)
    unmeasured = SolverResult(np.zeros(2), 0.0, Status.MAX_ITERATIONS, "budget", 1, 0.1)
    assert progress_of(failed) is Progress.NOT_CONTRACTING and progress_of(unmeasured) is Progress.NOT_CONTRACTING
    assert np.isnan(contraction(np.nan, 0.1)) and contraction(0.0, 0.0) == 0.0
