"""The paper's synchronisation task: the person leads x–y, their arm follows the height the robot leads; the
measures of arriving in step; the admittance and fixed-clock baselines."""

from dataclasses import replace

import numpy as np
import pytest

from comanip.simulation import ScenarioSetup, SyncSettings, TrialRecord
from comanip.simulation.following_arm import FollowedAxes, FollowingArm
from comanip.analysis.speed_profile import SETTLING_FRACTION
from comanip.simulation.measures import arrival_measures
from comanip.simulation.person import PersonParameters
from comanip.simulation.policies import POLICIES
from comanip.simulation.policies.admittance import AdmittancePolicy
from comanip.simulation.policies.onset_minimum_jerk import OnsetMinimumJerkPolicy
from comanip.simulation.policies.protocol import PolicyContext
from comanip.simulation.sync_scenario import person_axes, run_sync


def test_a_following_arm_resists_a_steady_lead_by_its_stiffness_times_its_lag():
    arm = FollowingArm(stiffness=200.0, damping=30.0, time_constant=0.1)
    parameters = PersonParameters(led_axes=(0, 1))
    followed = FollowedAxes((2,), arm, parameters.impedance_force)
    hold = np.array([0.3, 0.0, 0.52])
    followed.start(hold)
    speed, dt = -0.3, 0.001           # the robot leads the height down at 0.3 m/s
    holding = None
    for k in range(2000):
        t = k * dt
        position, velocity = np.array([0.3, 0.0, 0.5 + speed * t]), np.array([0.0, 0.0, speed if k else 0.0])
        intended, intended_velocity, force = hold.copy(), np.zeros(3), np.zeros(3)
        followed.apply(t, position, velocity, intended, intended_velocity, force)
        if holding is None:
            holding = force[2]
    # the weight held before the reach (800 N/m × 2 cm), and beyond it the lag's spring: K_f tau |v|, upward
    assert holding == pytest.approx(parameters.stiffness * 0.02)
    assert force[2] - holding == pytest.approx(arm.stiffness * arm.time_constant * -speed, rel=1e-2)
    assert intended[2] - position[2] == pytest.approx(0.02 - speed * arm.time_constant, rel=1e-2)
    assert intended_velocity[2] == pytest.approx(speed, rel=1e-2)      # the person takes up the lead's speed
    np.testing.assert_array_equal(intended[:2], hold[:2])                 # the led axes are untouched


@pytest.mark.parametrize("axes", [(), (3,), (0, 0), "xy"])
def test_led_axes_must_be_distinct_axis_indices(axes):
    with pytest.raises(ValueError, match="led_axes"):
        PersonParameters(led_axes=axes)


def test_the_person_leads_the_height_only_in_the_variant_or_when_the_robot_does_not():
    assert person_axes(SyncSettings(policy="forecast")) == (0, 1)
    assert person_axes(SyncSettings(policy="forecast", person_leads_height=True)) == (0, 1, 2)
    for name in ("passive", "admittance"):
        assert person_axes(SyncSettings(policy=name)) == (0, 1, 2)


def _record(t, position, goal) -> TrialRecord:
    zeros = np.zeros_like(position)
    velocity = np.gradient(position, t, axis=0)
    return TrialRecord(t=t, position=position, velocity=velocity, intended_position=position, intended_velocity=velocity,
                       rest_position=position, stiffness=zeros, person_force=zeros, robot_force=zeros, goal=goal)


def test_arrival_measures_match_hand_computations_on_minimum_jerk_axes():
    t = np.arange(0.0, 2.0001, 0.001)
    start, goal = np.array([0.3, 0.0, 0.5]), np.array([0.5, 0.2, 0.2])
    sigma = lambda s: 10 * s**3 - 15 * s**4 + 6 * s**5          # noqa: E731
    s_xy, s_z = np.clip(t / 1.0, 0.0, 1.0), np.clip((t - 0.2) / 1.0, 0.0, 1.0)    # z 0.2 s late
    position = np.column_stack([start[:2] + np.outer(sigma(s_xy), goal[:2] - start[:2]),
                                start[2] + sigma(s_z) * (goal[2] - start[2])])
    m = arrival_measures(_record(t, position, goal), (0, 1), (2,), mt=1.25)
    # a minimum-jerk speed 30 s²(1 - s)² / T falls below the fraction f of its peak (1.875 / T) at s(1 - s) = sqrt(1.875 f / 30)
    s_arrival = (1 + np.sqrt(1 - 4 * np.sqrt(1.875 * SETTLING_FRACTION / 30))) / 2
    assert m["person_arrival_s"] == pytest.approx(s_arrival, abs=2e-3)
    assert m["arrival_lag_mt"] == pytest.approx(0.2 / 1.25, abs=2e-3)
    assert m["person_peak_speed_s"] == pytest.approx(0.5, abs=2e-3) and m["peak_lag_mt"] == pytest.approx(0.2 / 1.25, abs=2e-3)
    assert m["height_error_at_arrival_m"] == pytest.approx((1 - sigma(s_arrival - 0.2)) * 0.3, rel=1e-2)


def _context(start, height=0.2) -> PolicyContext:
    from comanip import presets

    model = presets.cartesian()
    plan = SimpleNamespacePlan(np.linspace(0.0, 1.0, 101))
    return PolicyContext(start=np.r_[start, np.zeros(3)], prior_goal=np.array([0.5, 0.2, 0.2]), width=model.width,
                         observation_time=0.2, dt=0.01, duration=1.5, model=model, online_model=model,
                         online_width=model.width, estimator=None, prior_plan=plan, goal_height=height)


class SimpleNamespacePlan:
    """The two fields of a plan the context reads for its expected movement time: a 1 m/s-peaked bell over 1 s."""

    def __init__(self, t):
        self.t, self.ee_speed = t, np.sin(np.pi * t) ** 2


def test_the_admittance_robot_moves_its_rest_at_the_force_beyond_holding_over_its_damping():
    start = np.array([0.3, 0.0, 0.5])
    policy = AdmittancePolicy(_context(start), damping=40.0)
    for k in range(101):          # 1 s: holding 15 N, then 4 N more downward from 0.5 s on
        t = 0.01 * k
        policy.observe(t, start, np.zeros(3), np.array([0.0, 0.0, 15.0 - (4.0 if t >= 0.5 else 0.0)]))
    prediction = policy.predict(1.0)
    assert prediction.rest(1.0)[0][2] == pytest.approx(0.5 - 4.0 / 40.0 * 0.5, abs=1e-3)
    assert prediction.rest(1.0)[1][2] == pytest.approx(-4.0 / 40.0)
    assert np.all(np.isnan(prediction.goal)) and not AdmittancePolicy.leads_height


def test_the_onset_robot_reaches_the_height_after_its_fixed_duration():
    start = np.array([0.3, 0.0, 0.5])
    policy = OnsetMinimumJerkPolicy(_context(start, height=0.2), duration=0.8)
    rest = policy.predict(0.2).rest
    assert rest(0.4)[0][2] == pytest.approx(0.5 - 0.3 * 0.5)            # half way at half its duration
    assert rest(0.8)[0][2] == pytest.approx(0.2) and rest(1.2)[0][2] == pytest.approx(0.2)


class LateOnsetPolicy(OnsetMinimumJerkPolicy):
    """The fixed-clock robot started 0.4 s after the onset."""

    name = "late-onset"

    def __init__(self, context):
        super().__init__(context, onset=0.4)


@pytest.fixture(scope="module")
def task_runs():
    """Two trials each of the passive, the in-step (fixed clock from the onset) and the late robot, near goal, the
    model's person (~20 s: the tests that use it are marked slow)."""
    settings = SyncSettings(goal="near", trials=2)
    setup = ScenarioSetup(settings)
    POLICIES[LateOnsetPolicy.name] = LateOnsetPolicy
    try:
        return settings, {name: run_sync(replace(settings, policy=name), setup, progress=False)
                          for name in ("passive", "onset-minimum-jerk", LateOnsetPolicy.name)}
    finally:
        del POLICIES[LateOnsetPolicy.name]


def _median(trials, key):
    return float(np.median([trial.metrics[key] for trial in trials]))


@pytest.mark.slow
def test_a_robot_that_leads_the_height_late_loses_to_one_that_leads_it_in_step(task_runs):
    """Late: its speed peak comes well after the person's, and the person's horizontal arrival waits for the height
    (the handle still moves while the robot lowers it)."""
    _, runs = task_runs
    in_step, late = runs["onset-minimum-jerk"], runs[LateOnsetPolicy.name]
    assert _median(late, "peak_lag_mt") > abs(_median(in_step, "peak_lag_mt")) + 0.1
    assert _median(late, "person_arrival_s") > _median(in_step, "person_arrival_s")
    assert _median(late, "movement_time_s") > _median(in_step, "movement_time_s")


@pytest.mark.slow
def test_a_passive_robots_person_does_all_the_lifting(task_runs):
    settings, runs = task_runs
    for passive, leading in zip(runs["passive"], runs["onset-minimum-jerk"]):
        z = 2
        assert np.max(np.abs(passive.record.robot_force[:, z])) < 1e-5         # the robot holds nothing
        # the person brings the height to the goal themselves: their intention goes there
        assert abs(passive.record.intended_position[-1, z] - settings.goal[z]) < abs(
            passive.record.intended_position[0, z] - settings.goal[z]) / 5
        assert abs(passive.record.position[-1, z] - settings.goal[z]) < 0.01
        # with a robot leading the height the person intends none of it and does less work
        assert leading.metrics["person_work_J"] < passive.metrics["person_work_J"]
        assert np.max(np.abs(leading.record.robot_force[:, z])) > 1.0
