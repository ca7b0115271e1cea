"""Mean and covariance propagation against Monte Carlo of the noisy discrete dynamics."""

import numpy as np
import pytest

import comanip
from comanip.belief import NOISE_FORMS, propagate_belief, sample_trajectories
from comanip.belief.propagation import belief_step_function


@pytest.mark.parametrize("noise", NOISE_FORMS)
def test_propagation_matches_monte_carlo(noise, rng):
    model = comanip.presets.planar().replace(noise=noise)
    H = 20
    torque = np.column_stack([np.linspace(4, -3, H), np.linspace(1, 2, H)])
    s0 = np.array([0.0, 0.0, 0.1, -0.05])
    mean, cov = propagate_belief(model.body, model.h, model.kappa, s0, torque, noise)
    samples = sample_trajectories(model.body, model.h, model.kappa, s0, torque, 40_000, rng, noise)
    standard_error = np.sqrt(np.diag(cov[-1]) / len(samples))
    assert np.all(np.abs(samples[:, -1].mean(axis=0) - mean[-1]) <= 4 * standard_error + 1e-12)
    mc_cov = np.cov(samples[:, -1].T)
    # compare the well-determined entries: all of them for isotropic noise, the driven ones otherwise
    scale = np.sqrt(np.outer(np.diag(cov[-1]), np.diag(cov[-1])))
    assert np.all(np.abs(mc_cov - cov[-1]) <= 0.03 * scale + 1e-12)


def test_casadi_step_equals_numpy_rollout():
    model = comanip.presets.cartesian()
    step = belief_step_function(model.body, model.h, model.kappa, model.noise)
    torque = np.random.default_rng(1).normal(size=(5, 3))
    s0 = np.array([0.1, 0, 0, 0, 0.2, 0])
    mean, cov = propagate_belief(model.body, model.h, model.kappa, s0, torque)
    mu, Sigma = s0, np.zeros((6, 6))
    for tau in torque:
        mu, Sigma = (np.asarray(v) for v in step(mu, Sigma, tau))
        mu = mu.ravel()
    np.testing.assert_allclose(mu, mean[-1], rtol=1e-12)
    np.testing.assert_allclose(Sigma, cov[-1], rtol=1e-12, atol=1e-18)


def test_point_mass_step_is_the_papers_A_B():
    model = comanip.presets.planar()
    h, M, D = model.h, model.M, model.D
    from comanip.belief.propagation import linearised_step_function

    _, A, B = (np.asarray(v) for v in linearised_step_function(model.body, h)(np.zeros(4), np.zeros(2)))
    Minv = np.linalg.inv(M)
    np.testing.assert_allclose(A, np.block([[np.eye(2), h * np.eye(2)], [np.zeros((2, 2)), np.eye(2) - h * Minv @ D]]))
    np.testing.assert_allclose(B, np.vstack([np.zeros((2, 2)), h * Minv]))
