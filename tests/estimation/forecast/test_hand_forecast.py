"""The forecast of the hand (comanip.estimation.forecast.hand_forecast): a continuation from the hand's state that is the
model's own reach where the hand moves like the model, with the model's belief of the rest of the reach."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import comanip
from comanip.belief import sample_trajectories
from comanip.belief.propagation import linearised_step_function
from comanip.estimation.forecast import path_baselines
from comanip.estimation.forecast.hand_forecast import continued_reach
from comanip.estimation.model_reaches.model_families import default_families
from comanip.estimation.online.online_options import OnlineOptions
from comanip.estimation.model_reaches.reach_timing import movement_span


@pytest.fixture(scope="module")
def arm():
    model = comanip.presets.load("arm")
    families = default_families().families(model)
    o = OnlineOptions()
    family = families.family(model.width, o.family_distances, o.family_size, o.family_tolerance)
    transition = np.asarray(linearised_step_function(model.body, model.h)(np.zeros(model.state_size), np.zeros(model.n))[1])
    goal = np.array([0.15, 0.12, 0.05])                  # oblique: the forecast's frame is turned onto it
    plan = families.planner.solve(np.zeros(model.state_size), goal, model.width)
    assert plan.success
    return model, family, transition, goal, plan


def _own_forecast(arm, k, goal_covariance=None):
    """The forecast from step k of the model's own reach, at its own stop."""
    model, family, transition, goal, plan = arm
    stop = model.h * movement_span(plan.ee_speed).last
    return continued_reach(family, np.zeros(3), plan.t[k], plan.ee_mean[k], plan.ee_velocity[k], goal,
                           np.zeros((3, 3)) if goal_covariance is None else goal_covariance, stop)


@pytest.mark.parametrize("k", [4, 8, 12, 16])
def test_on_the_models_own_reach_the_forecast_is_its_rest(arm, k):
    model, _, _, _, plan = arm
    forecast = _own_forecast(arm, k)
    assert forecast.pace == pytest.approx(1.0, abs=0.1)
    leads = np.array([0.04, 0.1, 0.2])
    steps = k + np.round(leads / model.h).astype(int)
    assert np.abs(forecast.at(plan.t[k] + leads).position - plan.ee_mean[steps]).max() < 3e-3


def test_on_the_models_own_reach_the_forecast_is_close_to_replanning_from_the_hand(arm):
    model, family, _, goal, plan = arm
    k = 10
    replanned = comanip.Planner(model).solve(plan.mean[k], goal, model.width)
    forecast = _own_forecast(arm, k)
    leads = np.array([0.04, 0.1, 0.2])
    assert np.abs(forecast.at(plan.t[k] + leads).position - replanned.ee_mean[np.round(leads / model.h).astype(int)]).max() < 0.01


def test_it_starts_at_the_hands_state_and_ends_at_rest_on_the_goal(arm):
    _, family, transition, goal, _ = arm
    x, v, a = np.array([0.05, 0.02, 0.01]), np.array([0.6, 0.5, -0.2]), np.array([-3.0, 1.0, 2.0])
    forecast = continued_reach(family, np.zeros(3), 0.2, x, v, goal, np.zeros((3, 3)), 0.5, a)
    start = forecast.at(0.2)
    np.testing.assert_allclose(start.position[0], x, atol=1e-12)
    np.testing.assert_allclose(start.velocity[0], v, atol=1e-9)
    step = 1e-4
    ahead = forecast.at([0.2 + step, 0.2 + 2 * step])
    np.testing.assert_allclose((ahead.position[0] - x) / step, v, atol=0.01)          # its position moves with v
    acceleration = (-3 * v + 4 * ahead.velocity[0] - ahead.velocity[1]) / (2 * step)
    np.testing.assert_allclose(acceleration, a, atol=0.05)                              # ... accelerates with a
    end = forecast.at([forecast.stop_time, forecast.stop_time + 0.3])
    np.testing.assert_allclose(end.position, [goal, goal], atol=1e-9)
    np.testing.assert_allclose(end.velocity[1], 0.0)
    assert forecast.stop_time == pytest.approx(0.5)


def test_velocity_is_the_derivative_of_position_between_grid_times(arm):
    forecast = _own_forecast(arm, 6)
    times = np.linspace(forecast.t[0] + 0.01, forecast.stop_time - 0.01, 9)
    step = 1e-5
    difference = (forecast.at(times + step).position - forecast.at(times - step).position) / (2 * step)
    np.testing.assert_allclose(difference, forecast.at(times).velocity, atol=1e-4)


def test_its_belief_is_the_models_noise_still_to_come_by_monte_carlo(arm):
    model, _, _, _, plan = arm
    k = 8
    forecast = _own_forecast(arm, k)
    samples = sample_trajectories(model.body, model.h, model.kappa, plan.mean[k], plan.torque[k:], 4000,
                                  np.random.default_rng(3), model.noise)
    for lead_steps in (5, 10):
        empirical = np.cov(samples[:, lead_steps, :3].T)
        predicted = forecast.at(plan.t[k] + lead_steps * model.h).covariance[0]
        np.testing.assert_allclose(np.sqrt(np.trace(predicted)), np.sqrt(np.trace(empirical)), rtol=0.12)


def test_the_goals_uncertainty_is_carried_as_far_as_the_hand_goes(arm):
    goal_covariance = np.diag([1e-4, 4e-4, 9e-4])
    without, with_goal = _own_forecast(arm, 6), _own_forecast(arm, 6, goal_covariance)
    end = with_goal.at(with_goal.stop_time).covariance[0] - without.at(without.stop_time).covariance[0]
    np.testing.assert_allclose(end, goal_covariance, atol=1e-9)
    np.testing.assert_allclose(with_goal.at(with_goal.t[0]).covariance[0], 0.0, atol=1e-12)


def test_bad_times_are_refused(arm):
    with pytest.raises(ValueError, match="times"):
        _own_forecast(arm, 6).at([[0.1, 0.2]])


def test_the_online_estimate_carries_the_forecast_from_the_observed_hand():
    model = comanip.presets.load("arm")
    estimator = comanip.OnlineGoalEstimator(model, np.zeros(model.state_size))
    person = comanip.Planner(model).solve(np.zeros(model.state_size), [0.2, 0.05, 0.0], model.width)
    for i in range(1, 9):
        estimate = estimator.update(person.t[i], person.ee_mean[i], person.ee_velocity[i])
    assert estimate.path.t[0] == pytest.approx(person.t[8])
    np.testing.assert_allclose(estimate.path.position[0], person.ee_mean[8], atol=1e-12)
    np.testing.assert_allclose(estimate.path.velocity[0], person.ee_velocity[8], atol=1e-12)
    ahead = estimate.forecast.at(estimate.path.t)         # the path is the forecast on its own grid
    np.testing.assert_allclose(estimate.path.position, ahead.position, atol=1e-12)
    np.testing.assert_allclose(estimate.forecast.at(person.t[12]).position[0], person.ee_mean[12], atol=5e-3)


def test_minimum_jerk_baseline_meets_its_boundary_conditions():
    x, v, a, g = np.array([0.0, 0.1]), np.array([1.0, -0.5]), np.array([2.0, 3.0]), np.array([0.3, 0.2])
    T, step = 0.4, 1e-5
    path = path_baselines.minimum_jerk_to(x, v, a, g, T, [0.0, step, 2 * step, T, T - step, T - 2 * step, T + 1])
    np.testing.assert_allclose(path[0], x)
    np.testing.assert_allclose((path[1] - path[0]) / step, v, atol=1e-3)
    np.testing.assert_allclose((path[2] - 2 * path[1] + path[0]) / step**2, a, atol=0.1)
    np.testing.assert_allclose(path[3], g, atol=1e-12)
    np.testing.assert_allclose((path[3] - path[4]) / step, 0.0, atol=1e-3)
    np.testing.assert_allclose(path[6], g)


def test_recent_acceleration_is_the_slope_of_the_last_velocities():
    t = np.arange(20) * 0.008
    velocity = np.column_stack([1.0 + 5.0 * t, -2.0 * t])
    np.testing.assert_allclose(path_baselines.recent_acceleration(t, velocity), [5.0, -2.0])


@settings(max_examples=60)
@given(st.lists(st.floats(-0.4, 0.4), min_size=3, max_size=3), st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
       st.lists(st.floats(-40.0, 40.0), min_size=3, max_size=3), st.floats(-0.3, 0.8), st.floats(0.0, 1.0))
def test_any_hand_state_gives_a_bounded_forecast_that_ends_on_the_goal(arm, position, velocity, acceleration, stop_in, t_now):
    """Wherever the hand is and however it moves, the forecast stays near the line to the goal, within what its
    velocity and acceleration can carry it in the time left, and stops on the goal."""
    _, family, transition, goal, _ = arm
    x, v, a = np.array(position), np.array(velocity), np.array(acceleration)
    forecast = continued_reach(family, np.zeros(3), t_now, x, v, goal, 1e-4 * np.eye(3), t_now + stop_in, a)
    R = max(forecast.stop_time - t_now, 0.02)
    path = forecast.at(t_now + np.linspace(0.0, R + 0.1, 40))
    assert np.all(np.isfinite(path.position)) and np.all(np.isfinite(path.covariance))
    reach = np.linalg.norm(goal - x) + np.linalg.norm(v) * R + np.linalg.norm(a) * R**2
    assert np.linalg.norm(path.position - x, axis=1).max() <= 2 * reach + 1e-9
    np.testing.assert_allclose(path.position[-1], goal, atol=1e-9)
    assert np.all(np.linalg.eigvalsh(path.covariance) >= -1e-12)


def test_the_familys_transition_powers_are_the_models_step_map_repeated(arm):
    _, family, transition, _, _ = arm
    np.testing.assert_allclose(family.transition_powers[1], transition, rtol=0, atol=1e-15)
    np.testing.assert_allclose(family.transition_powers[3], transition @ transition @ transition, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(family.transition_powers[0], np.eye(family.nx))
