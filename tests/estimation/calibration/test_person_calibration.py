"""What the estimator learns of a person from their finished reaches: on the model's own reaches played at a
wrong pace (a person who is not the model), the calibrated estimates come nearer the endpoint, their 95 %
regions hold it more often and the forecast's hold the hand; on the model's own reaches nothing is invented; forgetting the person starts over."""

import numpy as np
import pytest
from scipy.stats import chi2

import comanip
from comanip.estimation import OnlineOptions
from comanip.estimation.calibration.person_calibration import CalibrationSettings, FinishedReach, PersonCalibration, reach_factors

REST_SAMPLES = 14


@pytest.fixture(scope="module")
def reaches(cartesian_planner):
    rng = np.random.default_rng(3)
    goals = [rng.uniform(0.2, 0.4) * (lambda u: u / np.linalg.norm(u))(rng.normal(size=3)) for _ in range(8)]
    return [cartesian_planner.solve(np.zeros(6), goal) for goal in goals]


def played(plan, pace):
    """The plan's hand played ``pace`` times slower (times s, positions m, velocities m/s), then at rest."""
    t, x, v = plan.t * pace, plan.ee_mean, plan.ee_velocity / pace
    rest = t[-1] + 0.01 * np.arange(1, REST_SAMPLES + 1)
    return np.r_[t, rest], np.vstack([x, np.repeat(x[-1:], REST_SAMPLES, 0)]), np.vstack([v, np.zeros((REST_SAMPLES, 3))])


def person_run(planner, reaches, pace, person, timing="model"):
    """Per reach: (median error / D, share of 95 % regions holding the endpoint, share of the forecast's 95 %
    regions at +0.2 s holding the hand), from 25 % to 90 % of it, each reach's estimator sharing ``person``
    (None: a new person every reach)."""
    out = []
    for plan in reaches:
        estimator = comanip.OnlineGoalEstimator(planner, np.zeros(6), options=OnlineOptions(timing=timing), person=person)
        t, x, v = played(plan, pace)
        end, errors, held, ahead = x[-1], [], [], []
        for k in range(1, len(t)):
            estimate = estimator.update(t[k], x[k], v[k])
            if 0.25 <= k / len(plan.t) <= 0.9:
                e = estimate.goal - end
                errors.append(np.linalg.norm(e) / np.linalg.norm(end))
                held.append(e @ np.linalg.solve(estimate.goal_covariance, e) <= chi2.ppf(0.95, 3))
                point = estimate.forecast.at([t[k] + 0.2])
                e = point.position[0] - np.array([np.interp(t[k] + 0.2, t, column) for column in x.T])
                ahead.append(e @ np.linalg.solve(point.covariance[0], e) <= chi2.ppf(0.95, 3))
        estimator.finish_reach()
        out.append((np.median(errors), np.mean(held), np.mean(ahead)))
    return np.array(out)


def test_calibration_converges_on_the_models_people_at_a_wrong_pace(cartesian_planner, reaches):
    person = PersonCalibration()
    calibrated = person_run(cartesian_planner, reaches, 0.7, person)
    uncalibrated = person_run(cartesian_planner, reaches, 0.7, None)
    later = slice(4, None)                                             # from the person's 5th reach on
    assert np.median(calibrated[later, 0]) < 0.6 * np.median(uncalibrated[later, 0]), (calibrated, uncalibrated)
    assert np.mean(calibrated[later, 1]) > np.mean(uncalibrated[later, 1]) + 0.15, (calibrated, uncalibrated)
    assert np.mean(calibrated[later, 2]) >= 0.8 > np.mean(uncalibrated[later, 2]) + 0.5, (calibrated, uncalibrated)
    assert person.reaches == len(reaches) and person.amplitude < 0.8    # ahead of the model's pace, less to go than it says
    np.testing.assert_allclose(calibrated[0], uncalibrated[0])                # the first reach: a person not seen yet


def test_a_person_who_is_the_model_is_left_as_the_model(cartesian_planner, reaches):
    person = PersonCalibration()
    calibrated = person_run(cartesian_planner, reaches[:5], 1.0, person)
    assert abs(person.amplitude - 1.0) < 0.01 and np.all(calibrated[:, 0] < 0.01) and np.all(calibrated[:, 1] >= 0.9)


def test_reset_keeps_the_person_and_forgetting_starts_over(cartesian_planner, reaches):
    estimator = comanip.OnlineGoalEstimator(cartesian_planner, np.zeros(6), options=OnlineOptions(timing="model"))
    t, x, v = played(reaches[0], 0.7)
    for k in range(1, len(t)):
        estimator.update(t[k], x[k], v[k])
    estimator.reset(np.zeros(6))                                     # learns from the reach it ends
    assert estimator.person.reaches == 1 and estimator.person.amplitude != 1.0
    estimator.reset(np.zeros(6))                                     # a reach with no observations teaches nothing
    assert estimator.person.reaches == 1
    first = estimator.update(t[10], x[10], v[10])
    estimator.forget_person()
    estimator.reset(np.zeros(6))
    fresh = comanip.OnlineGoalEstimator(cartesian_planner, np.zeros(6), options=OnlineOptions(timing="model"))
    np.testing.assert_array_equal(estimator.update(t[10], x[10], v[10]).goal, fresh.update(t[10], x[10], v[10]).goal)
    assert not np.allclose(first.goal, fresh.latest.goal)


def test_a_reach_that_did_not_stop_teaches_nothing(cartesian_planner, reaches):
    estimator = comanip.OnlineGoalEstimator(cartesian_planner, np.zeros(6))
    t, x, v = played(reaches[0], 1.0)
    for k in range(1, len(reaches[0].t) // 2):                       # interrupted mid-reach
        estimator.update(t[k], x[k], v[k])
    assert estimator.finish_reach() is None and estimator.person.reaches == 0


def test_the_factors_of_a_reach_that_stops_farther_and_later():
    t = np.linspace(0.0, 1.0, 101)
    goals = np.tile([0.2, 0.0, 0.0], (101, 1))                       # estimates say 0.2 m, stopping at 0.8 s
    hands = np.zeros((101, 3))
    hands[:, 0] = 0.1 * t                                            # the hand at 0.1 t m: still to go 0.3 - 0.1 t m, said 0.2 - 0.1 t
    reach = FinishedReach(np.zeros(3), np.array([0.3, 0.0, 0.0]), 0.0, 1.0, t, hands, goals,
                          np.tile(1e-4 * np.eye(3), (101, 1, 1)), np.full(101, 0.8), np.zeros((101, 3, 3)),
                          np.tile(np.eye(3), (101, 3, 1, 1)), t, hands)
    shown = reach_factors(reach)
    scored = t[(t >= 0.25) & (t <= 0.9)]
    assert shown.amplitude == pytest.approx(np.median((0.3 - 0.1 * scored) / (0.2 - 0.1 * scored)))
    scored = t[(t >= 0.25) & (t <= 0.9) & (0.8 - t > 0.02)]          # 25–90 % of the reach, a stop still ahead
    expected = np.median((1.0 - scored) / (0.8 - scored))
    assert shown.pace == pytest.approx(expected)


def test_bad_calibration_settings_are_refused_in_one_line():
    with pytest.raises(ValueError, match="new_person_spread must be a finite number > 0"):
        CalibrationSettings(new_person_spread=0.0)
    with pytest.raises(ValueError, match="person must be a PersonCalibration"):
        comanip.OnlineGoalEstimator(comanip.presets.cartesian(), np.zeros(6), person="alice")


def test_reset_sets_a_new_prior_goal_or_keeps_the_one_before(cartesian_planner):
    estimator = comanip.OnlineGoalEstimator(cartesian_planner, np.zeros(6), prior_goal=[0.3, 0.0, 0.0])
    estimator.reset(np.zeros(6))
    np.testing.assert_array_equal(estimator.prior_mean, [0.3, 0.0, 0.0])              # kept
    estimator.reset(np.r_[0.1, 0.0, 0.0, np.zeros(3)], prior_goal=[0.0, 0.4, 0.0])
    np.testing.assert_array_equal(estimator.update(0.01, [0.1, 0.0, 0.0], np.zeros(3)).goal, [0.0, 0.4, 0.0])
    estimator.reset(np.r_[0.1, 0.0, 0.0, np.zeros(3)], prior_goal=None)              # the start's position
    np.testing.assert_array_equal(estimator.prior_mean, [0.1, 0.0, 0.0])
    with pytest.raises(ValueError, match="prior_goal"):
        estimator.reset(np.zeros(6), prior_goal=[0.1, 0.2])


def led_run(planner, reaches, led_axes):
    """A person at the model's pace horizontally whose height a partner brings to 0.3 of where the model would:
    the calibration learned over their reaches by an estimator told the height is led (``led_axes``) or not."""
    person = PersonCalibration()
    options = OnlineOptions(timing="model", led_axes=led_axes, correction_time=0.3 if led_axes else None)
    for plan in reaches[:4]:
        estimator = comanip.OnlineGoalEstimator(planner, np.zeros(6), options=options, person=person)
        t, x, v = played(plan, 1.0)
        x, v = x * [1, 1, 0.3], v * [1, 1, 0.3]
        for k in range(1, len(t)):
            estimator.update(t[k], x[k], v[k])
        estimator.finish_reach()
    return person


def test_the_calibration_learns_nothing_from_the_axes_a_partner_leads(cartesian_planner, reaches):
    led, unled = led_run(cartesian_planner, reaches, (2,)), led_run(cartesian_planner, reaches, ())
    assert led.reaches == unled.reaches == 4
    assert abs(led.amplitude - 1.0) < 0.05 < abs(unled.amplitude - 1.0), (led.amplitude, unled.amplitude)


def test_a_calibration_on_some_axes_leaves_the_others_as_they_are():
    person = PersonCalibration()
    person._amplitudes, person.spread = [np.log(0.5)], 4.0            # a person who stops short, spread out
    rng = np.random.default_rng(0)
    root = rng.normal(size=(3, 3))
    hand, goal, covariance = rng.normal(size=3), rng.normal(size=3), root @ root.T
    new_goal, new_covariance = person.goal(hand, goal, covariance, axes=[0, 1])
    assert new_goal[2] == goal[2] and new_covariance[2, 2] == covariance[2, 2]
    np.testing.assert_allclose(new_goal[:2], hand[:2] + person.amplitude * (goal[:2] - hand[:2]))
    factor = person.spread * person.amplitude**2
    np.testing.assert_allclose(new_covariance[:2, :2], factor * covariance[:2, :2])
    assert np.linalg.eigvalsh(new_covariance).min() > 0
    everywhere = person.goal(hand, goal, covariance)
    np.testing.assert_allclose(everywhere[1], factor * covariance)
    np.testing.assert_allclose(person.goal(hand, goal, covariance, axes=[0, 1, 2])[1], everywhere[1])
