"""The online estimator composed of explanations: the first that explains the hand gives the estimate, a
user's own explanation plugs in, and the model-timing estimator is the own-pace explanation alone."""

import numpy as np
import pytest

from comanip.estimation import OnlineGoalEstimator, OnlineOptions
from comanip.estimation.explanations import Explained, HandAtRest, HandTrace, ModelAtOwnPace, ModelAtPersonPace, RecordedPeople
from comanip.estimation.estimate_status import EstimateStatus
from comanip.optim import Status


class FixedGoal:
    """An explanation that explains the hand, or not, with one goal."""

    def __init__(self, goal, explains):
        self.goal, self.explains, self.asked = np.asarray(goal, dtype=float), explains, 0

    def reset(self, reach):
        self.reach = reach

    def explain(self, hand, latest):
        self.asked += 1
        return Explained(self.goal, 1e-4 * np.eye(3), self.explains, Status.SOLVED, f"fixed at {self.goal.tolist()}")


def reach_samples(planner, goal):
    plan = planner.solve(np.zeros(6), goal)
    return plan.t[1:40], plan.ee_mean[1:40], plan.ee_velocity[1:40]


@pytest.fixture(scope="module")
def planner(cartesian_planner):
    OnlineGoalEstimator(cartesian_planner, np.zeros(6))       # builds the reach family once
    return cartesian_planner


def test_the_default_explanations_in_order(planner):
    kinds = [type(e) for e in OnlineGoalEstimator(planner, np.zeros(6)).explanations]
    assert kinds == [HandAtRest, ModelAtOwnPace, ModelAtPersonPace, RecordedPeople]
    assert [type(e) for e in OnlineGoalEstimator(planner, np.zeros(6), options=OnlineOptions(timing="model")).explanations] == [ModelAtOwnPace]


def test_the_first_explanation_that_explains_gives_the_estimate(planner):
    t, position, velocity = reach_samples(planner, np.array([0.3, 0.1, 0.0]))
    skipped, taken, never = FixedGoal([9.0, 0, 0], False), FixedGoal([0.2, 0.2, 0.2], True), FixedGoal([5.0, 0, 0], True)
    estimator = OnlineGoalEstimator(planner, np.zeros(6), explanations=[skipped, taken, never])
    for k in range(len(t)):
        estimate = estimator.update(t[k], position[k], velocity[k])
    np.testing.assert_array_equal(estimate.goal, taken.goal)
    assert never.asked == 0 and skipped.asked == taken.asked == len(t)
    assert estimate.message == "fixed at [9.0, 0.0, 0.0]; fixed at [0.2, 0.2, 0.2]"


def test_no_explanation_leaves_the_prior(planner):
    estimator = OnlineGoalEstimator(planner, np.zeros(6), prior_goal=[0.1, 0.2, 0.3], explanations=[FixedGoal([1.0, 0, 0], False)])
    estimate = estimator.update(0.05, np.array([0.01, 0.0, 0.0]), np.array([0.3, 0.0, 0.0]))
    assert estimate.status == EstimateStatus.UNINFORMATIVE
    np.testing.assert_array_equal(estimate.goal, [0.1, 0.2, 0.3])


def test_model_timing_is_the_own_pace_explanation_alone(planner):
    t, position, velocity = reach_samples(planner, np.array([0.25, -0.1, 0.05]))
    options = OnlineOptions(timing="model")
    by_timing = OnlineGoalEstimator(planner, np.zeros(6), options=options)
    composed = OnlineGoalEstimator(planner, np.zeros(6), explanations=[ModelAtOwnPace(planner.model, options)])
    for k in range(len(t)):
        a, b = by_timing.update(t[k], position[k], velocity[k]), composed.update(t[k], position[k], velocity[k])
        np.testing.assert_array_equal(a.goal, b.goal)
        np.testing.assert_array_equal(a.goal_covariance, b.goal_covariance)
    assert np.linalg.norm(a.goal - [0.25, -0.1, 0.05]) < 1e-3


def test_the_hand_trace_grows_past_its_first_block():
    trace = HandTrace(2)
    for k in range(200):
        trace.append(0.01 * k, np.array([k, -k], dtype=float), np.array([1.0, 2.0]))
    assert trace.count == 200 and trace.last_time == pytest.approx(1.99)
    np.testing.assert_array_equal(trace.position[:, 0], np.arange(200))
    np.testing.assert_array_equal(trace.last_observation, [199, -199, 1, 2])

