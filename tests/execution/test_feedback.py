"""Feedback from noisy, delayed observation: the observation model, the Kalman filter, the closed loop with it."""

import casadi as ca
import numpy as np
import pytest

from comanip.analysis import closed_loop_grid
from comanip.belief import propagate_belief, sample_trajectories
from comanip.belief.noise import sample_torque_error
from comanip.execution import DelayedKalmanFilter, Observation, execute_receding_horizon

GOAL, WIDTH = np.array([0.3, 0.0]), 0.02


# ---- the observation model ----------------------------------------------------------------------------------

@pytest.mark.parametrize("field", ["position_std", "velocity_std", "delay"])
@pytest.mark.parametrize("value", [-0.01, float("nan"), float("inf"), True, "0.1", None])
def test_bad_observation_settings_raise_a_one_line_error_naming_the_field(field, value):
    settings = {"position_std": 0.005, "velocity_std": 0.05, "delay": 0.1} | {field: value}
    with pytest.raises(ValueError, match=f"^{field} must be a finite number ≥ 0") as error:
        Observation(**settings)
    assert "\n" not in str(error.value)


def test_delay_is_rounded_to_whole_steps():
    assert [Observation(0, 0, delay).delay_steps(0.02) for delay in (0.0, 0.009, 0.03, 0.06, 0.1)] == [0, 0, 2, 3, 5]


def test_an_execution_rejects_an_observation_of_the_wrong_type(planar_planner):
    with pytest.raises(ValueError, match="observation must be None or a comanip.execution.Observation"):
        execute_receding_horizon(planar_planner, np.zeros(4), GOAL, WIDTH, steps=1, observation=(0.005, 0.05, 0.1))


# ---- the Kalman filter --------------------------------------------------------------------------------------

def _step_function(model):
    """s (nx,), executed torque (n,) -> next state: the arm's actual dynamics."""
    s, u = ca.SX.sym("s", model.state_size), ca.SX.sym("u", model.n)
    return ca.Function("step", [s, u], [model.body.discrete_step(s, u, model.h)])


@pytest.mark.slow
@pytest.mark.parametrize("activation", [(), (0.04, 0.04)])
def test_filter_covariance_matches_the_monte_carlo_of_its_errors(planar_planner, activation):
    # open loop with a fixed command sequence, so the filter's covariance is the same in every run: for a linear
    # body and Gaussian noise it is the exact covariance of the error (estimate - state), with or without unseen
    # activation stages; checked mid-reach and at the end, 3 steps of delay
    model = planar_planner.model.replace(activation=activation)
    torque = planar_planner.solve(np.zeros(4), GOAL, WIDTH).torque
    observation = Observation(position_std=0.005, velocity_std=0.05, delay=0.06)
    runs, rng, checked = 600, np.random.default_rng(1), [10, len(torque)]
    start = np.zeros(model.state_size)
    states = sample_trajectories(model.body, model.h, model.kappa, start, torque, runs, rng, model.noise)
    delay = observation.delay_steps(model.h)
    errors, predicted = np.zeros((runs, len(checked), model.state_size)), {}
    for r in range(runs):
        estimator = DelayedKalmanFilter(model, observation, start)
        for k, command in enumerate(torque, start=1):
            estimator.update(command, observation.measure(states[r, max(0, k - delay)], model.n, rng))
            if k in checked:
                errors[r, checked.index(k)] = estimator.mean - states[r, k]
                predicted[k] = np.diag(estimator.cov)
    np.testing.assert_allclose(np.mean(errors**2, axis=0), [predicted[k] for k in checked], rtol=0.15)
    assert np.all(np.abs(np.mean(errors, axis=0)) <= 4 * np.std(errors, axis=0) / np.sqrt(runs))   # unbiased


def test_filter_with_exact_feedback_knows_the_state_and_without_feedback_predicts_the_open_loop_belief(planar_planner, rng):
    model = planar_planner.model
    torque = planar_planner.solve(np.zeros(4), GOAL, WIDTH).torque
    exact = DelayedKalmanFilter(model, Observation(0.0, 0.0, 0.0), np.zeros(4))
    # a delay longer than the reach: the filter only predicts, so its estimate is the open-loop belief
    blind = DelayedKalmanFilter(model, Observation(0.005, 0.05, 10.0), np.zeros(4))
    step, state = _step_function(model), np.zeros(4)
    for command in torque:
        state = np.asarray(step(state, command + sample_torque_error(command, model.kappa, model.noise, rng))).ravel()
        exact.update(command, state)
        blind.update(command, np.zeros(4))
    np.testing.assert_allclose(exact.mean, state, atol=1e-12)
    assert np.max(np.abs(exact.cov)) < 1e-12
    mean, cov = propagate_belief(model.body, model.h, model.kappa, np.zeros(4), torque, model.noise)
    np.testing.assert_allclose(blind.mean, mean[-1], atol=1e-12)
    np.testing.assert_allclose(blind.cov, cov[-1], rtol=1e-9, atol=1e-15)


# ---- the closed loop with feedback --------------------------------------------------------------------------

def test_without_an_observation_the_closed_loop_is_the_exact_state_loop_bit_for_bit(planar_planner):
    # the exact-state loop written out: replan from the actual state, execute the first command with motor noise
    model, steps, rng = planar_planner.model, 12, np.random.default_rng(3)
    step = _step_function(model)
    states, plan = [np.zeros(4)], None
    for _ in range(steps):
        plan = planar_planner.solve(states[-1], GOAL, WIDTH,
                                    warm_start=None if plan is None else np.vstack([plan.torque[1:], plan.torque[-1:]]))
        executed = plan.torque[0] + sample_torque_error(plan.torque[0], model.kappa, model.noise, rng)
        states.append(np.asarray(step(states[-1], executed)).ravel())
    run = execute_receding_horizon(planar_planner, np.zeros(4), GOAL, WIDTH, steps=steps, rng=np.random.default_rng(3))
    assert np.array_equal(run.states, np.array(states)) and run.estimates is None


def test_noiseless_undelayed_observation_gives_the_exact_state_loop(planar_planner):
    exact = execute_receding_horizon(planar_planner, np.zeros(4), GOAL, WIDTH, steps=30, rng=np.random.default_rng(4))
    seen = execute_receding_horizon(planar_planner, np.zeros(4), GOAL, WIDTH, steps=30, rng=np.random.default_rng(4),
                                    observation=Observation(0.0, 0.0, 0.0))
    np.testing.assert_allclose(seen.states, exact.states, atol=1e-9)
    np.testing.assert_allclose(seen.estimates, exact.states, atol=1e-9)


def test_noisy_delayed_feedback_still_lands_near_the_goal(planar_planner, rng):
    # vision: 5 mm and 5 cm/s of noise, 100 ms late; seeds 0–5 ended 1–8 mm from the goal (exact state: < 3 mm)
    observation = Observation(position_std=0.005, velocity_std=0.05, delay=0.1)
    for _ in range(3):
        run = execute_receding_horizon(planar_planner, np.zeros(4), GOAL, WIDTH, steps=60, rng=rng, observation=observation)
        assert np.linalg.norm(run.ee[-1] - GOAL) < 2 * WIDTH
        assert run.ee_speed[-1] < 0.1 * run.ee_speed.max()
        error = run.estimates - run.states
        assert 0 < np.max(np.abs(error[:, :2])) < 0.03      # the person acts on a wrong but close estimate


def test_closed_loop_grid_passes_the_observation_on(planar_planner):
    observation = Observation(position_std=0.005, velocity_std=0.05, delay=0.1)
    outcome, = closed_loop_grid(planar_planner, [0.3], [WIDTH], n_trials=1, rng=np.random.default_rng(5), steps=15,
                                observation=observation)
    run = execute_receding_horizon(planar_planner, np.zeros(4), GOAL, WIDTH, steps=15, rng=np.random.default_rng(5),
                                   observation=observation)
    np.testing.assert_array_equal(outcome.velocity, run.ee_velocity)


def test_feedback_with_activation_stages_that_are_not_seen(activation_planner, rng):
    # the filter sees [q; qdot] and infers the two activation stages from the commands it sent
    observation = Observation(position_std=0.002, velocity_std=0.02, delay=0.04)
    run = execute_receding_horizon(activation_planner, np.zeros(4), GOAL, 0.04, steps=45, rng=rng, observation=observation)
    assert run.estimates.shape == (46, 8) and run.failed_replans == 0
    assert np.linalg.norm(run.ee[-1] - GOAL) < 0.04
    assert 0 < np.max(np.abs(run.estimates[:, 4:] - run.states[:, 4:])) < 0.5 * np.max(np.abs(run.states[:, 4:]))
