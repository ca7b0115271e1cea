"""A plan played at a person's timing: its onset and end where the timing puts them, and its velocities the
rate of its positions on the new clock."""

import numpy as np
import pytest

import comanip
from comanip.analysis.speed_profile import speed_metrics
from comanip.estimation.model_reaches.reach_timing import ReachTiming, movement_span, timed_plan


@pytest.fixture(scope="module")
def prediction():
    model = comanip.presets.arm()
    estimator = comanip.OnlineGoalEstimator(model, np.zeros(model.state_size))
    return model, estimator.reach.prediction(np.array([0.25, 0.05, -0.03]), order=0)


def test_without_a_timing_the_plan_runs_from_zero_at_the_models_pace(prediction):
    model, p = prediction
    timed = timed_plan(p.mean, p.cov, p.torque, model.h, model.n, None)
    np.testing.assert_array_equal(timed.t, model.h * np.arange(model.H + 1))
    assert timed.mean is p.mean and timed.cov is p.cov and timed.torque is p.torque


@pytest.mark.parametrize("onset, movement_time", [(0.15, 0.42), (0.0, 0.9), (0.4, 0.25)])
def test_a_timed_plan_moves_from_the_timings_onset_for_its_movement_time(prediction, onset, movement_time):
    model, p = prediction
    n = model.n
    timed = timed_plan(p.mean, p.cov, p.torque, model.h, n, ReachTiming(onset, movement_time))
    speed = np.linalg.norm(timed.mean[:, n:2 * n], axis=1)
    first, last = movement_span(speed)
    assert timed.t[first] == pytest.approx(onset, abs=1e-12)
    assert timed.t[last] - timed.t[first] == pytest.approx(movement_time, rel=1e-12)
    np.testing.assert_array_equal(timed.mean[:, :n], p.mean[:, :n])                 # the same path, on another clock
    # velocities are the rate of the positions on the new clock, as the plan's are on its own
    own = np.gradient(p.mean[:, :n], model.h, axis=0) - p.mean[:, n:2 * n]
    played = np.gradient(timed.mean[:, :n], timed.t, axis=0) - timed.mean[:, n:2 * n]
    pace = movement_time / (model.h * (last - first))
    np.testing.assert_allclose(played, own / pace, atol=1e-12)
    metrics = speed_metrics(timed.t - timed.t[0], speed)
    assert metrics.movement_time + timed.t[0] == pytest.approx(onset + movement_time, abs=timed.t[1] - timed.t[0])


def test_a_timing_without_a_movement_time_leaves_the_plan_as_it_is(prediction):
    model, p = prediction
    timed = timed_plan(p.mean, p.cov, p.torque, model.h, model.n, ReachTiming(0.2, 0.0))
    np.testing.assert_array_equal(timed.t, model.h * np.arange(model.H + 1))
