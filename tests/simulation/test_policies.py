"""Robot policies on the synchronisation scenario and the co-manipulation measures."""

import numpy as np
import pytest

from comanip.planning.starts.initial_guess import minimum_jerk
from comanip.simulation import ScenarioSetup, SyncSettings, TrialRecord
from comanip.simulation.measures import progress_toward, trial_measures
from comanip.simulation.policies import POLICIES
from comanip.simulation.policies.minimum_jerk_fit import fit_minimum_jerk
from comanip.simulation.policy_comparison import compare_sync_policies, comparison_rows, markdown_table

DURATION = 1.2          # s: a short trial (the reach is mostly done; the measures need only a record)


@pytest.fixture(scope="module")
def runs():
    """One short trial per policy to the near goal, the same person (seed 0) for all (~12 s: the tests
    that use it are marked slow)."""
    settings = SyncSettings(goal="near", trials=1, duration=DURATION)
    setup = ScenarioSetup(settings)
    results = compare_sync_policies({"near": settings}, list(POLICIES), setup)
    return settings, setup, {name: trials[0] for name, trials in results["near"].items()}, results


@pytest.mark.slow
def test_every_policy_meets_the_same_person_until_the_robot_acts(runs):
    settings, _, trials, _ = runs
    before = trials["passive"].record.t < settings.observation_time
    for name, trial in trials.items():
        # the person leads the height with a robot that does not: the same person among the robots alike
        reference = trials["passive" if not POLICIES[name].leads_height else "prior-only"].record
        np.testing.assert_allclose(trial.record.position[before], reference.position[before], atol=1e-12, err_msg=name)
        np.testing.assert_allclose(trial.record.person_force[before], reference.person_force[before], atol=1e-9, err_msg=name)


@pytest.mark.slow
def test_passive_robot_has_no_stiffness_no_force_and_no_estimate(runs):
    trial = runs[2]["passive"]
    assert np.all(trial.record.stiffness == 0.0)
    assert np.max(np.abs(trial.record.robot_force)) < 1e-5          # zero stiffness designs zero damping (to rounding)
    assert trial.metrics["work_against_robot_J"] < 1e-6
    assert trial.metrics["person_work_J"] > 0.05                     # the person moves arm and object alone
    assert np.isnan(trial.metrics["goal_error_mean_m"])


@pytest.mark.slow
def test_leading_policies_lead_z_only_from_the_observation_time(runs):
    settings, _, trials, _ = runs
    for name, trial in trials.items():
        if name == "passive":
            continue
        record, after = trial.record, trial.record.t >= settings.observation_time
        assert np.all(record.stiffness[~after] == 0.0), name
        np.testing.assert_array_equal(record.stiffness[after], np.tile([0.0, 0.0, settings.robot_stiffness], (after.sum(), 1)))
        if POLICIES[name].leads_height:       # the admittance robot follows the force and estimates no goal
            assert np.all(np.isnan(record.goal_estimate[~after])) and np.all(np.isfinite(record.goal_estimate[after])), name


@pytest.mark.slow
def test_prior_only_goal_error_is_the_prior_distance(runs):
    settings, _, trials, _ = runs
    distance = np.linalg.norm(np.subtract(settings.prior_goal, settings.goal))
    for key in ("goal_error_first_m", "goal_error_mean_m", "goal_error_final_m"):
        assert trials["prior-only"].metrics[key] == pytest.approx(distance, abs=1e-12)


@pytest.mark.slow
def test_constant_velocity_estimate_is_the_extrapolated_hand(runs):
    settings, setup, trials, _ = runs
    record = trials["constant-velocity"].record
    from comanip.simulation.sync_scenario import policy_context

    expected_time = policy_context(settings, setup, setup.settled_start(np.zeros(3))).expected_movement_time
    k = np.flatnonzero(record.t >= settings.observation_time - 1e-9)[0]      # the first update, at t_o
    extrapolated = record.position[k] + (expected_time - record.t[k]) * record.velocity[k]
    np.testing.assert_allclose(record.goal_estimate[k], extrapolated, atol=1e-12)
    for j in (1, 10, 30):                                                  # later updates, every 20 ms
        u = k + 20 * j
        np.testing.assert_allclose(record.goal_estimate[u], record.position[u] + (expected_time - record.t[u]) * record.velocity[u],
                                   atol=1e-12)
    assert trials["constant-velocity"].metrics["predictions"] == int(np.ceil((DURATION - settings.observation_time) / 0.02 - 1e-9)) + 1


@pytest.mark.slow
def test_one_shot_estimate_is_made_once_and_kept(runs):
    trial = runs[2]["one-shot"]
    finite = trial.record.goal_estimate[np.isfinite(trial.record.goal_estimate[:, 0])]
    np.testing.assert_array_equal(finite, np.tile(trial.estimate.goal, (len(finite), 1)))
    assert trial.metrics["predictions"] == 1


def test_minimum_jerk_fit_recovers_an_exact_minimum_jerk_prefix():
    start, goal, duration = np.array([0.3, 0.0, 0.47]), np.array([0.45, 0.45, 0.2]), 1.1
    t = np.arange(0.0, 0.5, 0.005)
    positions = minimum_jerk(start, np.zeros(3), goal, duration, t)[0]
    fit = fit_minimum_jerk(start, t, positions, prior_goal=[0.5, 0.2, 0.2], observation_std=1e-4)
    assert np.linalg.norm(fit.goal - goal) < 2e-3 and fit.duration == pytest.approx(duration, abs=5e-3)
    far_prior = fit_minimum_jerk(start, t[:10], positions[:10], prior_goal=[0.5, 0.2, 0.2])
    assert np.linalg.norm(far_prior.goal - goal) > 0.01      # 45 ms of a reach cannot fix its length: the prior shows


def _synthetic_record(t, position, person_force, robot_force, goal):
    velocity = np.gradient(position, t, axis=0)
    zeros = np.zeros_like(position)
    return TrialRecord(t=t, position=position, velocity=velocity, intended_position=position, intended_velocity=velocity,
                       rest_position=position, stiffness=zeros, person_force=person_force, robot_force=robot_force,
                       goal=np.asarray(goal, dtype=float))


def test_measures_match_hand_computations_on_a_synthetic_record():
    t = np.arange(0.0, 2.0001, 0.001)
    s = np.clip(t / 1.0, 0.0, 1.0)
    # x–y move linearly to the goal in 1 s; z moves the same way but 0.1 s later
    start, goal = np.array([0.3, 0.0, 0.5]), np.array([0.5, 0.2, 0.2])
    s_z = np.clip((t - 0.1) / 1.0, 0.0, 1.0)
    position = np.column_stack([start[:2] + np.outer(s, goal[:2] - start[:2]), start[2] + s_z * (goal[2] - start[2])])
    person_force = np.tile([3.0, 4.0, 0.0], (len(t), 1))             # |F| = 5 N throughout ...
    person_force[t >= 0.5, 0] += 2.0                                   # ... then 2 N more along x
    robot_force = np.tile([0.0, 0.0, 10.0], (len(t), 1))             # pushes up while z moves down at 0.3 m/s
    record = _synthetic_record(t, position, person_force, robot_force, goal)
    m = trial_measures(record, width=0.02)
    later_share = np.mean(t >= 0.5)
    assert m["rms_force_N"] == pytest.approx(np.sqrt(25 * (1 - later_share) + (25 + 2 * 2 * 3 + 4) * later_share))
    assert m["peak_force_N"] == pytest.approx(np.hypot(5.0, 4.0))
    assert m["rms_force_change_N"] == pytest.approx(2.0 * np.sqrt(later_share))
    assert m["work_against_robot_J"] == pytest.approx(10.0 * 0.3, rel=2e-3)   # F · distance against it
    assert m["person_work_J"] == pytest.approx(2.0 * 0.1, rel=2e-3)      # 2 N over the last 0.1 m of x
    assert m["sync_lag_s"] == pytest.approx(0.1, abs=2e-3)
    gap = np.clip(s - s_z, 0, None)[t <= m["movement_time_s"]]
    assert m["sync_error_rms"] == pytest.approx(np.sqrt(np.mean(gap**2)), rel=1e-6)
    assert m["completion_time_s"] == pytest.approx(1.1 - 0.01 / 0.3, abs=2e-3)   # z last within w/2 = 1 cm
    assert np.isnan(m["goal_error_mean_m"])
    np.testing.assert_allclose(progress_toward(position[:, :2], goal[:2])[[0, 500, 1000]], [0.0, 0.5, 1.0], atol=1e-12)
    later = trial_measures(record, width=0.02, from_time=1.5)           # z stopped: no work after 1.1 s
    assert later["work_against_robot_J"] == 0.0
    with pytest.raises(ValueError, match="from_time"):
        trial_measures(record, width=0.02, from_time=3.0)
    with pytest.raises(ValueError, match="width"):
        trial_measures(record, width=0.0)


@pytest.mark.slow
def test_comparison_table_shows_median_and_quartiles(runs):
    rows = comparison_rows(runs[3])
    assert [row["policy"] for row in rows] == list(POLICIES)
    prior = next(row for row in rows if row["policy"] == "prior-only")
    assert prior["goal_error_mean_m_median"] == pytest.approx(1e3 * np.hypot(0.05, 0.05))
    table = markdown_table(rows)
    assert table.count("\n") == len(rows) + 2 and "| near | passive (n=1) | – |" in table


def test_unknown_policy_and_policy_for_handover_are_rejected():
    with pytest.raises(ValueError, match="policy must be one of"):
        SyncSettings(policy="clairvoyant")
    from comanip.cli.main import main

    assert main(["simulate", "handover", "--policy", "passive", "--trials", "1"]) == 2


@pytest.mark.slow
def test_continuous_estimate_is_revised_at_every_update(runs):
    settings, _, trials, _ = runs
    record = trials["continuous"].record
    after = record.t >= settings.observation_time - 1e-9
    revisions = np.count_nonzero(np.any(np.diff(record.goal_estimate[after], axis=0) != 0, axis=1))
    assert trials["continuous"].metrics["predictions"] == trials["constant-velocity"].metrics["predictions"]
    assert revisions == trials["continuous"].metrics["predictions"] - 1      # a new goal at every update after the first


def test_continuous_policy_does_not_lead_before_its_first_observation():
    """With its first observation after t_o (a long update_interval) the continuous policy has no estimate at
    t_o: it must not lead (None), and it predicts once an observation came."""
    from comanip import presets
    from comanip.simulation.policies import ContinuousPolicy, PolicyContext

    model = presets.cartesian()
    start = np.r_[0.4, 0.0, 0.3, np.zeros(3)]
    context = PolicyContext(start=start, prior_goal=np.array([0.6, 0.1, 0.3]), width=model.width, observation_time=0.2,
                            dt=0.01, duration=1.5, model=model, online_model=model, online_width=model.width, estimator=None, prior_plan=None,
                            update_interval=0.5)
    policy = ContinuousPolicy(context)
    policy.observe(0.2, start[:3], np.zeros(3), np.zeros(3))
    assert policy.predict(0.2) is None
    policy.observe(0.5, start[:3] + [0.02, 0.0, 0.0], np.array([0.2, 0.0, 0.0]), np.zeros(3))
    prediction = policy.predict(0.5)
    assert prediction is not None and np.all(np.isfinite(prediction.goal))


@pytest.mark.parametrize("options, name", [(dict(observation_std=0.0), "observation_std"), (dict(prior_std=-1.0), "prior_std"),
                                           (dict(duration_bounds=(2.0, 1.0)), "duration_bounds"),
                                           (dict(duration_bounds=(0.0, 1.0)), "duration_bounds")])
def test_minimum_jerk_fit_refuses_bad_options_with_a_value_error_naming_them(options, name):
    with pytest.raises(ValueError, match=name):
        fit_minimum_jerk(np.zeros(3), [0.1, 0.2], np.full((2, 3), 0.01), np.full(3, 0.3), **options)


def test_sync_metrics_of_a_movement_that_ends_before_the_observation_time_are_nan_not_an_error():
    from comanip.simulation.sync_scenario import sync_metrics

    t = np.arange(0.0, 2.0001, 0.001)
    s = np.clip(t / 0.5, 0.0, 1.0)                                      # done in 0.5 s, before t_o = 1 s
    start, goal = np.array([0.3, 0.0, 0.5]), np.array([0.5, 0.2, 0.2])
    position = start + np.outer(s, goal - start)
    record = _synthetic_record(t, position, np.zeros_like(position), np.zeros_like(position), goal)
    metrics, _, _ = sync_metrics(record, goal, position, 0.02, observation_time=1.0)
    assert metrics["movement_time_s"] < 1.0
    assert np.isnan(metrics["rms_error_xy_m"]) and np.isnan(metrics["max_error_z_m"])
    assert metrics["goal_error_m"] == 0.0


def test_people_rows_weigh_every_effort_of_the_candidate_against_each_baseline():
    from types import SimpleNamespace

    from comanip.simulation.policy_comparison import CANDIDATE, people_rows, people_table

    def trials(goal_error, forecast_error, force, work, peak):
        return [SimpleNamespace(metrics={"goal_error_mean_m": goal_error + 0.001 * k, "forecast_error_mean_m": forecast_error,
                                         "rms_force_change_N": force + k, "person_work_J": work + 0.1 * k,
                                         "peak_force_change_N": peak}) for k in range(3)]

    nan = float("nan")
    results = {"arm": {"near": {"passive": trials(nan, nan, 10.0, 2.0, 30.0), "constant-velocity": trials(0.05, 0.02, 12.0, 0.5, 40.0),
                                CANDIDATE: trials(0.04, 0.03, 11.0, 1.0, 35.0)}}}
    row, = people_rows(results)
    assert row["goal_error_below"] is True and row["forecast_error_below"] is False
    assert row["goal_error_difference_mm"][0] == pytest.approx(-10.0)
    assert row["forecast_error_difference_mm"][0] == pytest.approx(10.0)
    assert row["force_change_above"] == ["passive"] and row["work_above"] == ["constant-velocity"]
    assert row["peak_force_above"] == ["passive"]
    assert row["work_excess_constant-velocity_J"][0] == pytest.approx(0.5)
    table = people_table([row], ["passive", "constant-velocity", CANDIDATE], "work", goal_error=False)
    assert "goal error" not in table and "**constant-velocity (+0.5 ± " in table
    table = people_table([row], ["passive", "constant-velocity", CANDIDATE], "force_change")
    assert "forecast error" in table and "yes, **no**" in table


def test_the_continuous_policy_estimates_with_the_online_preset():
    from comanip.simulation import ScenarioSetup, SyncSettings
    from comanip.simulation.policies import ContinuousPolicy
    from comanip.simulation.sync_scenario import policy_context

    with pytest.raises(ValueError, match="online_preset"):
        SyncSettings(online_preset="no-such-preset")
    settings = SyncSettings(online_preset="arm")
    setup = ScenarioSetup(settings)
    context = policy_context(settings, setup, setup.settled_start(np.zeros(3)))
    policy = ContinuousPolicy(context)
    assert policy.estimator.model.name == "arm" and policy.estimator.width == context.online_model.width
    assert context.model.name != "arm"                                   # the other policies keep the scenario's model


def test_forecast_error_is_the_mean_over_predictions_of_the_rms_distance_to_the_handle():
    from comanip.simulation.rest_trajectory import RestTrajectory
    from comanip.simulation.sync_scenario import forecast_error

    t = np.arange(0.0, 1.0001, 0.001)
    position = np.column_stack([0.3 + 0.2 * t, np.zeros_like(t), 0.5 - 0.3 * t])
    record = _synthetic_record(t, position, np.zeros_like(position), np.zeros_like(position), position[-1])
    exact = RestTrajectory(position, np.gradient(position, t, axis=0), 0.0, 0.001)
    shifted = RestTrajectory(position + [0.0, 0.01, 0.0], np.gradient(position, t, axis=0), 0.0, 0.001)
    assert forecast_error(record, [(0.2, exact)], until=0.8) == pytest.approx(0.0, abs=1e-12)
    assert forecast_error(record, [(0.2, exact), (0.4, shifted)], until=0.8) == pytest.approx(0.005)
    assert np.isnan(forecast_error(record, [(0.9, shifted)], until=0.8))       # made after MT: it forecasts nothing
    assert np.isnan(forecast_error(record, [], until=0.8))


def test_the_forecast_lead_descends_with_the_person_and_no_faster_than_the_goal_is_sure():
    from comanip.simulation.policies.forecast import height_along

    start, goal = np.array([0.3, 0.0, 0.5]), np.array([0.5, 0.0, 0.2])
    path = start + np.outer(np.linspace(0.0, 1.2, 13), goal - start)       # along the chord, and past the goal
    sure = np.zeros((3, 3))
    progress, z = height_along(path, start, goal, sure, height=0.2)
    np.testing.assert_allclose(progress, np.minimum(np.linspace(0.0, 1.2, 13), 1.0), atol=1e-12)
    np.testing.assert_allclose(z, 0.5 - 0.3 * progress, atol=1e-12)
    unsure, _ = height_along(path, start, goal, np.diag([0.01, 0.01, 1.0]), height=0.2)
    assert np.all(unsure[1:] < progress[1:]) and unsure[-1] < 1.0            # the expected distance is longer
    _, z_only = height_along(path + [0.0, 0.0, -0.1], start, goal, sure, height=0.2)
    np.testing.assert_allclose(z_only, z, atol=1e-12)                         # the led axis does not move the lead


def test_a_robot_that_gives_way_goes_its_share_of_the_way_from_the_handle_to_the_lead():
    from types import SimpleNamespace

    from comanip.simulation.policies import Prediction
    from comanip.simulation.rest_trajectory import RestTrajectory
    from comanip.simulation.sync_scenario import PolicyRobot

    lead = RestTrajectory(np.tile([0.4, 0.1, 0.3], (10, 1)), np.tile([0.0, 0.0, -0.2], (10, 1)), 0.0, 0.001)

    class Leading:
        name, update_interval, leads_height = "leading", None, True

        def observe(self, t, position, velocity, force):
            pass

        def predict(self, t):
            return Prediction(np.zeros(3), lead, lead_share=0.25)

    controller = SimpleNamespace(translational_stiffness=None)
    robot = PolicyRobot(controller, Leading(), SyncSettings(observation_time=0.001, known_height=False))
    state = SimpleNamespace(position=np.array([0.3, 0.0, 0.5]), velocity=np.array([0.1, 0.0, 0.0]))
    position, velocity = robot.command(0.002, state, np.zeros(3))
    np.testing.assert_allclose(position, [0.3, 0.0, 0.5 + 0.25 * (0.3 - 0.5)])       # x–y follow the handle
    np.testing.assert_allclose(velocity, [0.1, 0.0, 0.25 * -0.2])
    with pytest.raises(ValueError, match="lead_share"):
        Prediction(np.zeros(3), lead, lead_share=1.5)
