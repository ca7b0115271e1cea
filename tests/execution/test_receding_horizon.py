"""Closed-loop execution: without noise it reproduces the plan; with noise it still lands on the goal."""

import numpy as np

from comanip.execution import execute_receding_horizon


def test_noiseless_closed_loop_starts_like_the_plan_and_ends_on_the_goal(planar_planner):
    plan = planar_planner.solve(np.zeros(4), [0.3, 0.0], 0.02)
    run = execute_receding_horizon(planar_planner, np.zeros(4), [0.3, 0.0], 0.02, noise=False)
    # the first replan is the plan itself; later ones differ (the window recedes and Sigma restarts at 0),
    # but the noiseless reach still ends at rest on the goal
    np.testing.assert_allclose(run.commanded[0], plan.torque[0], rtol=1e-3)
    assert np.linalg.norm(run.ee[-1] - [0.3, 0.0]) < 0.005
    assert run.ee_speed[-1] < 0.1 * run.ee_speed.max()


def test_noisy_closed_loop_lands_within_the_goal(planar_planner, rng):
    ends = np.array([execute_receding_horizon(planar_planner, np.zeros(4), [0.3, 0.0], 0.02, rng=rng).ee[-1] for _ in range(4)])
    assert np.all(np.linalg.norm(ends - [0.3, 0.0], axis=1) < 0.02)


def test_a_model_with_activation_stages_runs_in_closed_loop(activation_planner, rng):
    # at H = 30 the planner keeps this model still for w ≤ 0.02 (zero torque is a stationary point), so the
    # reach aims at a 4 cm goal
    run = execute_receding_horizon(activation_planner, np.zeros(4), [0.3, 0.0], 0.04, steps=45, rng=rng)
    assert run.states.shape == (46, 8) and run.failed_replans == 0
    assert np.linalg.norm(run.ee[-1] - [0.3, 0.0]) < 0.04
    np.testing.assert_allclose(run.ee_velocity, run.states[:, 2:4])   # J = I: the velocity is qdot, not a stage
