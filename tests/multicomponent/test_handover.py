"""Authority handover: when the robot lets go, the stiffness schedule, the force it implies, bad input."""

import json

import numpy as np
import pytest

import comanip
from comanip.belief.propagation import sample_trajectories
from comanip.cli.main import main
from comanip.multicomponent.handover import plan_handover, stiffness_profile
from comanip.multicomponent.transition_model import TransitionModel

GOAL = [0.3, 0.1, 0.0]


@pytest.fixture(scope="module")
def transition_model():
    return TransitionModel()


@pytest.fixture(scope="module")
def plan(cartesian_planner):
    plan = cartesian_planner.solve(np.zeros(6), GOAL)
    assert plan.success
    return plan


def test_authority_passes_the_first_time_the_plan_is_within_the_predicted_distance(plan, transition_model):
    schedule = plan_handover(plan, transition_model)
    D = np.linalg.norm(np.asarray(GOAL))
    expected, _ = transition_model.predict(D, plan.width)
    assert schedule.status == "within_plan"
    assert schedule.transition_distance == pytest.approx(expected)
    assert np.linalg.norm(schedule.transition_position - GOAL) == pytest.approx(expected, abs=1e-6)
    before = schedule.t < schedule.transition_time
    assert np.all(schedule.distance_to_goal[before] > expected)
    # the rest position passes through the plan's own samples
    np.testing.assert_allclose(schedule.rest_position[np.isin(schedule.t, plan.t)], plan.ee_mean, atol=1e-12)


def test_stiffness_schedule_is_monotone_from_400_to_0(plan, transition_model):
    schedule = plan_handover(plan, transition_model, rate=1000.0)
    K, t = schedule.stiffness, schedule.t
    assert K[0] == 400.0 and K[-1] == 0.0
    assert np.all(np.diff(K) <= 0)
    assert np.all(K[t <= schedule.transition_time] == 400.0)
    assert np.all(K[t >= schedule.transition_time + schedule.ramp_time] == 0.0)
    assert np.allclose(np.diff(t), 1e-3)
    # the ramp spends the stated bound (no slower, no faster) and leaves the rest trajectory smooth
    assert np.max(np.abs(np.diff(K))) == pytest.approx(schedule.stiffness_step_bound, rel=1e-3)
    assert np.max(np.abs(np.diff(schedule.rest_velocity, axis=0))) < 1e-3 * 5.0   # |a| < 5 m/s² per 1 ms sample


def test_implied_impedance_force_has_no_jump_beyond_the_stated_bound(plan, transition_model, rng):
    # hands spread about the plan as the motor-control model predicts; force F = K (x_r - x) at 1 kHz
    model = comanip.presets.cartesian()
    states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 40, rng)

    def largest_jump(ramp_time):
        schedule = plan_handover(plan, transition_model, ramp_time=ramp_time, rate=1000.0)
        t = np.minimum(schedule.t, plan.t[-1])
        hands = np.stack([np.column_stack([np.interp(t, plan.t, s[:, k]) for k in range(3)]) for s in states])
        deviation = schedule.rest_position - hands                                  # (samples, T, 3)
        force = schedule.stiffness[None, :, None] * deviation
        jump = np.max(np.linalg.norm(np.diff(force, axis=1), axis=2))
        # what a constant 400 N/m spring would show for the same hands, plus the ramp's stated share
        spring = 400.0 * np.max(np.linalg.norm(np.diff(deviation, axis=1), axis=2))
        stated = schedule.force_step_bound(np.max(np.linalg.norm(deviation, axis=2)))
        at_switch = 400.0 * np.max(np.linalg.norm(deviation[:, np.searchsorted(t, schedule.transition_time)], axis=1))
        return jump, spring + stated, at_switch

    jump, bound, _ = largest_jump(0.2)
    assert jump <= bound
    # the paper's instantaneous switch drops the whole force held at the switch within one sample
    step_jump, _, held = largest_jump(0.0)
    assert step_jump > bound and step_jump > 10 * jump
    assert step_jump == pytest.approx(held, rel=0.05)


def test_handover_at_the_start_when_the_transition_lies_beyond_the_goal_distance(plan, rng):
    ratio, width = (v.ravel() for v in np.meshgrid([0.2, 0.5, 0.8], [0.01, 0.03, 0.05]))
    far = TransitionModel((ratio, width, 0.5 + 0.1 * ratio + rng.normal(0, 0.002, 9)))   # transitions ~0.55 m out
    schedule = plan_handover(plan, far, ramp_time=0.1)
    assert schedule.status == "at_start" and schedule.transition_time == 0.0
    assert schedule.stiffness[0] == 400.0 and schedule.stiffness[-1] == 0.0


def test_stiffness_profile_ramp_law():
    K = stiffness_profile([0.0, 0.1, 0.15, 0.2, 0.3, 0.4], transition_time=0.1, ramp_time=0.2)
    np.testing.assert_allclose(K, [400.0, 400.0, 200.0 * (1 + np.cos(np.pi / 4)), 200.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_array_equal(stiffness_profile([0.1, 0.1 + 1e-9], 0.1, 0.0), [400.0, 0.0])   # T_r = 0: a step


@pytest.mark.parametrize("kwargs, match", [
    (dict(ramp_time=-0.1), "ramp_time must be a finite number ≥ 0"),
    (dict(ramp_time=float("nan")), "ramp_time"),
    (dict(rate=0.0), "rate must be a finite number > 0"),
    (dict(leading_stiffness=-400.0), "leading_stiffness"),
])
def test_bad_handover_arguments_are_rejected(plan, transition_model, kwargs, match):
    with pytest.raises(ValueError, match=match):
        plan_handover(plan, transition_model, **kwargs)


def test_handover_needs_a_plan_and_a_fitted_model(plan, transition_model):
    with pytest.raises(ValueError, match="plan must be a comanip.Plan"):
        plan_handover(plan.ee_mean, transition_model)
    with pytest.raises(ValueError, match="fitted"):
        plan_handover(plan, TransitionModel(data=None))


def test_handover_command_writes_the_schedule(tmp_path, capsys):
    code = main(["handover", "--goal", "0.25,0.1,0", "--rate", "500", "--out", str(tmp_path), "--no-plot", "--verbose"])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    saved = json.loads((tmp_path / "handover_0.json").read_text())
    assert saved["transition_time_s"] == report[0]["transition_time_s"]
    rows = np.genfromtxt(tmp_path / "handover_0.csv", delimiter=",", names=True)
    assert np.allclose(np.diff(rows["t_s"]), 2e-3) and rows["stiffness_N_per_m"][0] == 400.0


def _release_on_the_exact_path(schedule, trigger):
    """Drive a HandoverRobot with the schedule's own rest motion at 1 kHz (noiseless, exact hand states)."""
    from types import SimpleNamespace

    from comanip.simulation.handover_scenario import HandoverRobot

    robot = HandoverRobot(SimpleNamespace(translational_stiffness=None), schedule, 1e-3, trigger)
    for t, position, velocity in zip(schedule.t, schedule.rest_position, schedule.rest_velocity):
        robot.command(t, SimpleNamespace(position=position, velocity=velocity), np.zeros(3))
    return robot


def _estimate_release(plan, transition_model, settle_fraction, fallback_time):
    from comanip.estimation import LoopSettings
    from comanip.estimation.streaming import online_settings
    from comanip.simulation.handover_release import EstimateRelease

    described = online_settings.load("correcting").replace(width=plan.width, loop=LoopSettings(segmentation=None, rate=50.0))
    loop = described.estimation_loop(plan.start, prior_goal=GOAL)
    loop.begin(0.0, plan.start[:3])
    return EstimateRelease(loop, transition_model, plan.width, settle_fraction, fallback_time)


def test_estimate_triggered_release_follows_the_goal_distance_one_on_an_exact_reach(plan, transition_model):
    from comanip.simulation.handover_release import GoalDistanceRelease

    schedule = plan_handover(plan, transition_model, rate=1000.0)
    known = _release_on_the_exact_path(schedule, GoalDistanceRelease(schedule))
    estimated = _release_on_the_exact_path(schedule, _estimate_release(plan, transition_model, 0.25, plan.t[-1]))
    assert known.trigger.cause == "goal_distance" and estimated.trigger.cause == "estimate"
    assert abs(known.switch_time - schedule.transition_time) <= 1e-3
    # exact estimate of the goal from ~0.52 s on, but the corrected-deviation belief keeps its std above
    # 0.25 T until ~0.6 s: the release comes 43 ms later, about two 20 ms updates
    assert 0.0 <= estimated.switch_time - known.switch_time <= 0.05
    metrics = estimated.trigger.metrics(np.asarray(GOAL))
    assert not metrics["release_fallback"] and metrics["estimate_status"] is not None
    assert metrics["estimate_goal_error_m"] < 0.1 * schedule.goal_distance
    assert metrics["estimate_goal_std_m"] <= 0.25 * metrics["estimated_transition_distance_m"]
    assert metrics["estimated_transition_distance_m"] == pytest.approx(schedule.transition_distance, rel=0.1)


def test_an_estimate_that_never_settles_releases_at_the_fallback_time_and_says_so(plan, transition_model):
    schedule = plan_handover(plan, transition_model, rate=1000.0)
    robot = _release_on_the_exact_path(schedule, _estimate_release(plan, transition_model, 1e-9, plan.t[-1]))
    assert robot.switch_time == pytest.approx(plan.t[-1], abs=1e-3)
    metrics = robot.trigger.metrics(np.asarray(GOAL))
    assert metrics["release_cause"] == "fallback_plan_end" and metrics["release_fallback"]
    assert metrics["estimate_updates"] > 0


def test_unknown_release_trigger_is_rejected():
    from comanip.simulation import HandoverSettings

    with pytest.raises(ValueError, match="release_trigger must be one of goal_distance, estimate"):
        HandoverSettings(release_trigger="time")
    with pytest.raises(ValueError, match="settle_fraction"):
        HandoverSettings(release_trigger="estimate", settle_fraction=0.0)
