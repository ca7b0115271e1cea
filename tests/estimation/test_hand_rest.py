"""Rest judged from positions: a tracked hand's noisy velocities do not make it move, before or after a reach."""

import numpy as np

import comanip
from comanip.estimation.hand_rest import REST_RADIUS_M, REST_WINDOW_S, has_left, resting_position, too_far_apart_to_rest


def noisy_reach(seed=0, step=0.01, noise=1e-3):
    """A 0.3 m minimum-jerk reach in 3-D from 0.3 s to 0.9 s, positions with ``noise`` m, backward-difference velocities."""
    t = np.arange(0.0, 1.6, step)
    goal = np.array([0.18, 0.24, 0.0])
    s = np.clip((t - 0.3) / 0.6, 0, 1)[:, None]
    position = goal * (10 * s**3 - 15 * s**4 + 6 * s**5) + np.random.default_rng(seed).normal(0, noise, (len(t), 3))
    velocity = np.r_[np.zeros((1, 3)), np.diff(position, axis=0) / step]
    return t, position, velocity, goal


def test_rest_is_read_from_positions_within_the_radius_over_the_window():
    t = np.arange(0.0, 0.3, 0.01)
    still = np.random.default_rng(1).normal(0, 1e-3, (len(t), 3))
    assert not has_left(still, np.zeros(3)) and has_left(still + [0, 0, 2 * REST_RADIUS_M], np.zeros(3))
    np.testing.assert_allclose(resting_position(t, still), still[t >= t[-1] - REST_WINDOW_S - 1e-9].mean(axis=0))
    moving = still + np.outer(t, [0.2, 0, 0])                    # 0.2 m/s: 20 mm in the window
    assert resting_position(t, moving) is None
    assert resting_position(t[:5], still[:5]) is None            # seen for less than the window
    creeping = np.outer(t, [0.03, 0, 0])                         # 3 cm/s: 3 mm in the window, inside the radius
    assert resting_position(t, creeping) is not None and resting_position(t, creeping, creep=0.02) is None


def test_a_window_whose_ends_are_too_far_apart_to_rest_has_no_rest():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 1.5 * REST_WINDOW_S, 0.004)
    first = int(np.searchsorted(t, t[-1] - REST_WINDOW_S))
    refused = 0
    for spread, drift in rng.uniform([0.2, 0.0], [3.0, 3.0], (400, 2)):
        position = (rng.normal(0, spread * REST_RADIUS_M / 2, (len(t), 3))
                    + np.outer(t / REST_WINDOW_S, rng.normal(0, drift * REST_RADIUS_M, 3)))
        if too_far_apart_to_rest(position[first], position[-1]):
            refused += 1
            assert resting_position(t, position) is None
    assert 50 < refused < 350                                    # both kinds of window were drawn


def test_a_hand_resting_between_two_points_more_than_a_radius_apart_still_rests():
    t = np.arange(0.0, 0.3, 0.01)
    position = np.zeros((len(t), 3))
    position[:, 0] = np.where(np.arange(len(t)) % 2, 0.9, -0.9) * REST_RADIUS_M   # samples 1.8 radii apart
    assert not too_far_apart_to_rest(position[0], position[1])
    assert resting_position(t, position) is not None


def test_a_noisy_tracked_hand_keeps_one_status_before_its_reach_and_its_goal_once_it_rests():
    t, position, velocity, goal = noisy_reach()
    model = comanip.presets.arm()
    estimator = comanip.OnlineGoalEstimator(model, np.zeros(model.state_size))
    statuses, goals = [], []
    for k in range(len(t)):
        estimate = estimator.update(t[k], position[k], velocity[k])
        statuses.append(estimate.status)
        goals.append(estimate.goal)
    before = t < 0.3
    assert set(statuses[: int(before.sum())]) == {"uninformative"}
    settled = np.array(goals)[t >= 1.1]                           # 0.2 s after the hand stopped, to the end
    assert np.max(np.linalg.norm(settled - goal, axis=1)) < REST_RADIUS_M
