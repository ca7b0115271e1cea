"""The smoothed goal: drift passes on at once, a step is spread over a few time constants, the covariance says how
far the smoothed goal lies from the evidence, and on recorded arm reaches it jumps less at little cost."""

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import comanip
from comanip.estimation import OnlineOptions
from comanip.estimation.calibration.goal_smoothing import GoalSmoother, GoalSmoothing

ARMS = Path(__file__).resolve().parents[4] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
DT = 0.008
START = np.zeros(3)


def test_a_goal_drifting_below_the_free_rate_passes_on_at_once():
    smoother = GoalSmoother(GoalSmoothing(free_rate=4.0, time_constant=0.016), START)
    hand = np.array([0.05, 0.0, 0.0])
    for k in range(30):                          # the goal drifts at 3 reach distances per second
        raw = np.array([0.3, 0.0, 0.0]) * (1 + 3.0 * DT) ** k
        smoothed, covariance = smoother.smooth(k * DT, raw, 1e-4 * np.eye(3), hand)
        np.testing.assert_allclose(smoothed, raw, rtol=1e-12)
        np.testing.assert_allclose(covariance, 1e-4 * np.eye(3), rtol=1e-12)


def test_a_step_is_spread_over_a_few_time_constants():
    smoothing = GoalSmoothing(free_rate=3.75, time_constant=0.016)
    smoother = GoalSmoother(smoothing, START)
    hand = np.array([0.05, 0.0, 0.0])
    before, after = np.array([0.3, 0.0, 0.0]), np.array([0.3, 0.1, 0.0])
    smoother.smooth(0.0, before, np.eye(3) * 1e-4, hand)
    previous, moved = before, []
    for k in range(1, 40):
        smoothed, covariance = smoother.smooth(k * DT, after, np.eye(3) * 1e-4, hand)
        moved.append(np.linalg.norm(smoothed - previous))
        offset = smoothed - after
        np.testing.assert_allclose(covariance, np.eye(3) * 1e-4 + np.outer(offset, offset), atol=1e-15)
        previous = smoothed
    free = smoothing.free_rate * DT * 0.3
    first = free + (1 - math.exp(-DT / smoothing.time_constant)) * (0.1 - free)
    assert moved[0] == pytest.approx(first, rel=1e-9) and moved[0] < 0.5 * 0.1
    assert np.all(np.diff(moved) <= 1e-15)                             # never faster than at the step
    assert np.linalg.norm(previous - after) < 1e-3                    # settled after 20 time constants


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1)), min_size=2, max_size=30),
       st.floats(0.001, 0.05))
def test_the_smoothed_goal_moves_towards_the_estimate_and_never_past_it(goals, dt):
    smoother = GoalSmoother(GoalSmoothing(), START)
    previous = None
    for k, goal in enumerate(goals):
        goal = np.array(goal)
        smoothed, covariance = smoother.smooth(k * dt, goal, 1e-4 * np.eye(3), np.array([0.1, 0.0, 0.0]))
        if previous is not None:
            step, wanted = smoothed - previous, goal - previous
            # on the segment from the previous smoothed goal to the estimate
            assert np.linalg.norm(np.cross(step, wanted)) <= 1e-9 * (1 + np.linalg.norm(wanted)) ** 2
            assert step @ wanted >= -1e-12 and np.linalg.norm(step) <= np.linalg.norm(wanted) + 1e-12
        assert np.linalg.eigvalsh(covariance).min() >= 1e-4 * (1 - 1e-9)
        previous = smoothed


def test_bad_smoothing_options_are_refused_in_one_line():
    with pytest.raises(ValueError, match="time_constant must be a finite number > 0"):
        GoalSmoothing(time_constant=0.0)
    with pytest.raises(ValueError, match="free_rate must be a finite number > 0"):
        GoalSmoothing(free_rate=-1.0)
    with pytest.raises(ValueError, match="goal_smoothing must be a GoalSmoothing or None"):
        OnlineOptions(goal_smoothing=0.016)


def test_the_estimate_keeps_the_unsmoothed_goal(cartesian_planner):
    plan = cartesian_planner.solve(np.zeros(6), np.array([0.3, 0.1, 0.0]))
    smoothed = comanip.OnlineGoalEstimator(cartesian_planner, np.zeros(6))
    unsmoothed = comanip.OnlineGoalEstimator(cartesian_planner, np.zeros(6), options=OnlineOptions(goal_smoothing=None))
    for k in range(1, 30):
        a = smoothed.update(plan.t[k], plan.ee_mean[k], plan.ee_velocity[k])
        b = unsmoothed.update(plan.t[k], plan.ee_mean[k], plan.ee_velocity[k])
        np.testing.assert_array_equal(a.unsmoothed_goal, b.goal)           # the same evidence, the same explanation
        np.testing.assert_array_equal(b.goal, b.unsmoothed_goal)
        offset = a.goal - a.unsmoothed_goal
        np.testing.assert_allclose(a.goal_covariance, a.unsmoothed_goal_covariance + np.outer(offset, offset), atol=1e-15)
        np.testing.assert_allclose(a.forecast.at([plan.t[-1]]).position[0], a.goal, atol=1e-9)   # the forecast stops there


@pytest.mark.skipif(not ARMS.is_dir(), reason="the recorded arm reaches (../shared/data/arm_reaches) are not beside this clone")
def test_on_recorded_arm_reaches_the_goal_jumps_less_at_little_cost():
    """After a quarter of the movement, the smoothed goal moves by more than 0.1 D in at most half as many updates
    as the unsmoothed one, and at half of the movement it is at most 0.01 D farther from the endpoint (median)."""
    from comanip.recordings import load_tathum
    model = comanip.presets.arm()
    jumps, unsmoothed_jumps, cost = 0, 0, []
    for r in [trial.streamed_recording() for trial in load_tathum(ARMS)[::9]]:
        estimator = comanip.OnlineGoalEstimator(model, np.r_[r.position[0], np.zeros(model.state_size - 3)])
        goals, raw, t = [], [], []
        for k in range(r.seen_until(1.0)):
            estimate = estimator.update(r.t[k], r.position[k], r.velocity[k])
            goals.append(estimate.goal), raw.append(estimate.unsmoothed_goal), t.append(r.t[k])
            if k + 1 == r.seen_until(0.5):
                cost.append((np.linalg.norm(estimate.goal - r.end) - np.linalg.norm(estimate.unsmoothed_goal - r.end)) / r.distance)
        late = np.array(t[1:]) >= r.onset + 0.25 * r.movement_time
        jumps += int(np.sum((np.linalg.norm(np.diff(goals, axis=0), axis=1) / r.distance > 0.1)[late]))
        unsmoothed_jumps += int(np.sum((np.linalg.norm(np.diff(raw, axis=0), axis=1) / r.distance > 0.1)[late]))
    assert unsmoothed_jumps > 0 and jumps <= 0.5 * unsmoothed_jumps, (jumps, unsmoothed_jumps)
    assert np.median(cost) <= 0.01, np.median(cost)
