"""The closed-form expected reward against Monte Carlo, and its W forms."""

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from comanip.objectives.reward import expected_reward, goal_covariance


def _random_spd(rng, d, scale):
    A = rng.normal(size=(d, d))
    return scale * (A @ A.T / d + 0.2 * np.eye(d))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), d=st.sampled_from([2, 3]), width=st.floats(0.01, 0.05))
def test_expected_reward_matches_monte_carlo(seed, d, width):
    rng = np.random.default_rng(seed)
    goal = rng.normal(scale=0.05, size=d)
    Sigma = _random_spd(rng, d, 0.02**2)
    W = goal_covariance(width, d, "std")
    # the hand within about one combined standard deviation of the goal, where a reward is worth estimating
    mu = goal + np.linalg.cholesky(Sigma + W) @ rng.normal(scale=0.7, size=d)
    closed = expected_reward(mu, Sigma, goal, W)
    # E_x[N(x; g, W)] with x ~ N(mu, Sigma), by sampling x
    x = rng.multivariate_normal(mu, Sigma, size=400_000)
    e = x - goal
    density = np.exp(-0.5 * np.einsum("ij,jk,ik->i", e, np.linalg.inv(W), e)) / np.sqrt(np.linalg.det(2 * np.pi * W))
    estimate = density.mean()
    standard_error = density.std() / np.sqrt(len(density))
    assume(standard_error < 0.005 * closed)  # the sample resolves the reward to well under 2 %
    assert abs(estimate - closed) <= 0.02 * closed


def test_goal_covariance_forms():
    np.testing.assert_allclose(goal_covariance(0.02, 2, "std"), 4e-4 * np.eye(2))
    np.testing.assert_allclose(goal_covariance(0.02, 3, "cov"), 0.02 * np.eye(3))


def test_reward_decreases_with_distance_and_spread():
    W = goal_covariance(0.02, 2)
    g = np.zeros(2)
    near = expected_reward(np.array([0.01, 0]), np.zeros((2, 2)), g, W)
    far = expected_reward(np.array([0.05, 0]), np.zeros((2, 2)), g, W)
    spread = expected_reward(np.zeros(2), 1e-3 * np.eye(2), g, W)
    on_goal = expected_reward(np.zeros(2), np.zeros((2, 2)), g, W)
    assert on_goal > near > far and on_goal > spread
