"""The online estimator's MAP goal (comanip.estimation.online.map_goal): -log p's gradient, Hessian and Gauss–Newton matrix
against finite differences, and MapNewton's goal against the observations' own goal and a search of -log p."""

import numpy as np
import pytest
import scipy.optimize

from comanip.estimation.estimate_status import EstimateStatus
from comanip.estimation.online.map_goal import MapNewton, MapProblem
from comanip.estimation.online.observation_whitening import ObservationWhitening
from comanip.estimation.model_reaches.reach_family import ReachFamily

WIDTH = 0.02
STEPS = np.array([4, 7, 10, 13])
TRUE_GOAL = np.array([0.28, 0.07])


@pytest.fixture(scope="module")
def family(planar_planner):
    return ReachFamily(planar_planner, WIDTH)


def _problem(family, observed_noise=None, prior_std=1.0):
    """A MAP problem whose observations (positions m, velocities m/s at ``STEPS``) are the mean of the plan to
    ``TRUE_GOAL`` plus ``observed_noise``, with a prior of ``prior_std`` m about a goal 5 cm off, and a whitening of
    correlated observation errors (a random walk in the state, 3 mm / 3 cm/s observation noise)."""
    start = np.zeros(2)
    m = 2 * family.n
    weights = np.eye(family.H + 1)[STEPS]
    observed = weights @ family.prediction(start, TRUE_GOAL, order=0, covariance=False).mean[:, :m]
    if observed_noise is not None:
        observed = observed + observed_noise
    prior_mean = TRUE_GOAL + np.array([0.05, -0.03])
    problem = MapProblem(family, lambda goal: family.prediction(start, goal, order=2, covariance=False), start, prior_mean,
                         np.eye(2) / prior_std**2, STEPS, observed, weights)
    walk = np.arange(family.H + 1)[:, None, None] * np.diag([1e-6, 1e-6, 1e-4, 1e-4])
    powers = np.broadcast_to(np.eye(family.nx), (family.H + 1, family.nx, family.nx))
    noise = np.broadcast_to(np.diag([9e-6, 9e-6, 9e-4, 9e-4]), (len(STEPS), m, m))
    return problem, ObservationWhitening(walk, powers, m, STEPS, noise)


def _whitened_residual(problem, whitening, goal):
    predicted = problem.weights @ problem.prediction(goal).mean[:, :problem.m]
    return whitening.apply((problem.observed - predicted)[:, :, None]).ravel()


def test_the_gradient_hessian_and_gauss_newton_matrix_are_the_derivatives_of_minus_log_p(family):
    """Central differences (1e-6 m) of -log p give its gradient (minus ``descent``), of the gradient its Hessian,
    and of the whitened residual r the Gauss–Newton matrix JᵀJ + P0⁻¹, at a goal the observations do not fit."""
    problem, whitening = _problem(family, prior_std=0.1)
    goal = TRUE_GOAL + np.array([0.03, -0.02])
    terms = problem.terms(whitening, goal)
    step = 1e-6
    shifts = step * np.eye(2)
    gradient = np.array([(problem.terms(whitening, goal + e).objective - problem.terms(whitening, goal - e).objective) / (2 * step)
                         for e in shifts])
    np.testing.assert_allclose(-terms.descent, gradient, rtol=1e-6, atol=1e-6 * np.abs(gradient).max())
    hessian = np.array([(problem.terms(whitening, goal - e).descent - problem.terms(whitening, goal + e).descent) / (2 * step)
                        for e in shifts])
    np.testing.assert_allclose(terms.hessian, hessian, rtol=1e-5, atol=1e-5 * np.abs(hessian).max())
    jacobian = np.column_stack([(_whitened_residual(problem, whitening, goal + e) - _whitened_residual(problem, whitening, goal - e))
                                / (2 * step) for e in shifts])
    expected = jacobian.T @ jacobian + problem.prior_precision
    np.testing.assert_allclose(terms.gauss_newton, expected, rtol=1e-6, atol=1e-6 * np.abs(expected).max())
    assert not np.allclose(terms.hessian, terms.gauss_newton)  # the residuals' curvature is in the Hessian


def test_map_newton_returns_the_goal_of_observations_on_its_plan_and_its_laplace_covariance(family):
    """Observations on the plan's mean and a weak prior: from 4 cm away the MAP goal is the plan's goal, the gradient
    vanishes there (the last Newton step taken), and the covariance is the inverse of the last Hessian."""
    problem, whitening = _problem(family, prior_std=10.0)
    result = MapNewton(problem, whitening, tolerance=1e-10, step_fraction=0.5, width=WIDTH).solve(TRUE_GOAL + [0.03, 0.025], 50)
    assert result.success, result.message
    np.testing.assert_allclose(result.x, TRUE_GOAL, atol=1e-5)
    terms = result.local_model
    np.testing.assert_allclose(terms.covariance() @ terms.hessian, np.eye(2), atol=1e-9)
    first = problem.terms(whitening, TRUE_GOAL + np.array([0.03, 0.025]))
    assert np.abs(problem.terms(whitening, result.x).descent).max() < 1e-6 * np.abs(first.descent).max()


def test_map_newton_finds_the_minimum_a_search_of_minus_log_p_finds(family, rng):
    """Noisy observations and a prior 5 cm off: the MAP goal is where Nelder–Mead, started elsewhere on -log p's
    values alone, ends, and -log p is no lower 1 mm away along either axis."""
    m = 2 * family.n
    noise = np.c_[rng.normal(scale=0.003, size=(len(STEPS), m // 2)), rng.normal(scale=0.03, size=(len(STEPS), m // 2))]
    problem, whitening = _problem(family, observed_noise=noise, prior_std=0.05)
    result = MapNewton(problem, whitening, tolerance=1e-10, step_fraction=0.5, width=WIDTH).solve(problem.prior_mean, 50)
    assert result.success, result.message

    def objective(goal):
        return problem.terms(whitening, np.asarray(goal)).objective

    search = scipy.optimize.minimize(objective, TRUE_GOAL - [0.04, 0.02], method="Nelder-Mead",
                                     options={"xatol": 1e-9, "fatol": 1e-12, "maxiter": 4000})
    np.testing.assert_allclose(result.x, search.x, atol=1e-6)
    assert result.fun <= search.fun + 1e-9
    for shift in 1e-3 * np.r_[np.eye(2), -np.eye(2)]:
        assert objective(result.x + shift) > result.fun


def test_map_newton_says_when_its_goal_is_the_end_of_the_familys_range(family):
    """Observations of a reach to a goal beyond the family's largest distance: the MAP goal stops at the range's end
    and says so (status at_range_end, no success); to a goal inside the range it does not."""
    far = TRUE_GOAL * (1.5 * family.distances[-1] / np.linalg.norm(TRUE_GOAL))
    problem, whitening = _problem(family, prior_std=10.0)
    start = np.zeros(2)
    weights = np.eye(family.H + 1)[STEPS]
    beyond = MapProblem(family, problem.predict, start, problem.prior_mean, problem.prior_precision, STEPS,
                        weights @ _stretched_mean(family, start, far)[:, :problem.m], weights)
    result = MapNewton(beyond, whitening, tolerance=1e-10, step_fraction=0.5, width=WIDTH).solve(TRUE_GOAL, 50)
    assert result.status == EstimateStatus.AT_RANGE_END and not result.success
    assert np.linalg.norm(result.x) == pytest.approx(family.distances[-1], rel=1e-6)
    inside = MapNewton(problem, whitening, tolerance=1e-10, step_fraction=0.5, width=WIDTH).solve(TRUE_GOAL, 50)
    assert inside.status != EstimateStatus.AT_RANGE_END and inside.success


def _stretched_mean(family, start, goal):
    """The mean of the family's plan to the range's end on ``goal``'s direction, its positions and velocities scaled
    out to ``goal``: a hand moving farther than any plan of the family."""
    end = goal * (family.distances[-1] / np.linalg.norm(goal))
    mean = family.prediction(start, end, order=0, covariance=False).mean.copy()
    mean[:, :2 * family.n] *= np.linalg.norm(goal) / family.distances[-1]
    return mean
