"""Closed-loop execution: without noise it reproduces the plan; with noise it still lands on the goal."""

import numpy as np
import pytest

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


def test_the_executed_cost_of_a_loop_at_the_models_step_is_the_objective_on_what_it_did(planar_planner):
    # cycles of h: the states fall on the model's steps, and the cost is J with no covariance on the actual path
    from comanip.execution import executed_cost
    from comanip.objectives.reach_objective import reach_objective

    problem, model = planar_planner.problem, planar_planner.model
    run = execute_receding_horizon(planar_planner, np.zeros(4), [0.3, 0.0], 0.02, rng=np.random.default_rng(1))
    expected = reach_objective(run.ee, np.zeros((len(run.ee), 2, 2)), run.executed, np.array([0.3, 0.0]), 0.02,
                               problem.weights, model.nu, problem.reward)
    assert executed_cost(planar_planner, run, 0.02) == pytest.approx(expected, rel=1e-12)


def test_a_loop_faster_than_the_model_step_reaches_a_goal_that_jumps(planar_planner):
    jumped = np.array([0.3, 0.2])
    run = execute_receding_horizon(planar_planner, np.zeros(4), [0.3, 0.0], 0.02, iterations=2, period=0.005,
                                   rng=np.random.default_rng(2), goal_jumps=[(0.15, jumped)])
    assert len(run.t) == 121 and np.allclose(np.diff(run.t), 0.005)   # H·h / period cycles
    np.testing.assert_allclose(run.goals[:30], [[0.3, 0.0]] * 30)
    np.testing.assert_allclose(run.goals[30:], [jumped] * 90)
    assert np.linalg.norm(run.ee[-1] - jumped) < 0.02 and len(run.replan_statuses) == 120


def test_an_observation_model_needs_cycles_of_the_model_step(planar_planner):
    from comanip.execution import Observation

    with pytest.raises(ValueError, match="noisy or delayed observation"):
        execute_receding_horizon(planar_planner, np.zeros(4), [0.3, 0.0], 0.02, period=0.01,
                                 observation=Observation(0.005, 0.05, 0.1))


def test_a_replanner_brings_its_own_budget(planar_planner):
    from comanip.planning import Replanner

    with pytest.raises(ValueError, match="its own budget"):
        execute_receding_horizon(Replanner(planar_planner), np.zeros(4), [0.3, 0.0], 0.02, iterations=2)


def test_a_replanning_without_a_preparation_is_named_before_the_loop_runs(planar_planner):
    class OnlyReplans:  # what a replanning needed before cycles were prepared after the command
        planner = planar_planner

        def first_plan(self, start, goal, width=None):
            raise AssertionError("the loop must not start")

        def replan(self, previous, state, elapsed, goal=None, width=None):
            raise AssertionError("the loop must not start")

    with pytest.raises(ValueError, match="OnlyReplans has no prepare"):
        execute_receding_horizon(OnlyReplans(), np.zeros(4), [0.3, 0.0], 0.02)
