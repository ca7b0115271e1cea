"""Simulated people who are not the model: a person at another pace, a person whose intended path is a recording."""

from pathlib import Path

import numpy as np
import pytest

from comanip.recordings.recording import Recording
from comanip.simulation.person import PersonParameters, SimulatedPerson
from comanip.simulation.recorded_person import (END_HOLD, PLAYBACK_LEAD, RecordedPerson, recorded_reach, surface_normal,
                                                usable_for_reach)

GOAL = np.array([0.30, 0.10, -0.15])
ARMS = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"


def _intentions(planner, pace: float, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The intended positions and velocities (K, 3) of a noiseless person at those times (s), their hand following
    their intention exactly (each re-plan sees the intention's last position)."""
    parameters = PersonParameters(pace=pace, motor_noise=False, anticipates_inertia=False)
    person = SimulatedPerson(planner, parameters, GOAL, 0.05, np.random.default_rng(0))
    person.start(np.zeros(3))
    hand, velocity = np.zeros(3), np.zeros(3)
    positions, velocities = [], []
    for t in times:
        person.force(t, hand, velocity)
        hand, velocity = person.intended_position.copy(), person.intended_velocity.copy()
        positions.append(hand)
        velocities.append(velocity)
    return np.array(positions), np.array(velocities)


@pytest.mark.parametrize("pace", [0.7, 1.3])
def test_an_off_pace_persons_intention_is_the_models_at_the_scaled_time(cartesian_planner, pace):
    times = np.arange(0.0, 1.5, 0.005)
    model_position, model_velocity = _intentions(cartesian_planner, 1.0, times)
    position, velocity = _intentions(cartesian_planner, pace, pace * times)
    assert np.linalg.norm(model_position[-1]) > 0.2            # the reach is under way
    np.testing.assert_allclose(position, model_position, atol=1e-9)
    np.testing.assert_allclose(velocity, model_velocity / pace, atol=1e-9)


def _synthetic_recording(angle: float, distance: float = 0.2, bulge: float = 0.02) -> Recording:
    """A planar reach from (1, 2) m at rest for 0.1 s, then a minimum-jerk movement of distance (m) at angle (rad)
    over 0.5 s with a sideways bulge (m, to the left of the direction) peaking mid-way."""
    step = 0.01
    t = np.arange(0.0, 0.6 + step / 2, step)
    s = np.clip((t - 0.1) / 0.5, 0.0, 1.0)
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    along = np.array([np.cos(angle), np.sin(angle)])
    left = np.array([-along[1], along[0]])
    position = np.array([1.0, 2.0]) + np.outer(distance * progress, along) + np.outer(bulge * np.sin(np.pi * s), left)
    return Recording(name="synthetic", t=t, position=position, velocity=np.gradient(position, step, axis=0), onset=0.1,
                     end_time=0.6)


@pytest.mark.parametrize("angle", [0.0, 2.0, -2.5])
def test_a_recorded_path_starts_at_the_start_and_ends_at_the_scaled_turned_endpoint(angle):
    start = np.array([0.31, 0.0, 0.47])
    goal = np.array([0.45, 0.15, 0.20])
    t, position = recorded_reach(_synthetic_recording(angle), start, goal)
    assert t[0] == 0.0 and t[-1] == pytest.approx(PLAYBACK_LEAD + 0.5 + END_HOLD)
    np.testing.assert_allclose(position[0], start, atol=1e-12)
    np.testing.assert_allclose(position[-1], goal, atol=1e-12)
    # mid-movement the bulge is sideways, horizontal and scaled by the reach's distance over the recording's
    reach = goal - start
    middle = int(np.argmin(np.abs(t - (PLAYBACK_LEAD + 0.25))))
    offset = position[middle] - (start + 0.5 * reach)
    scale = np.linalg.norm(reach) / 0.2
    np.testing.assert_allclose(offset @ reach / np.linalg.norm(reach), 0.0, atol=3e-4)   # mid-way, to the low-pass
    sideways = offset - (offset @ reach) / (reach @ reach) * reach
    assert sideways[2] == pytest.approx(0.0, abs=1e-12)
    assert np.linalg.norm(sideways) == pytest.approx(0.02 * scale, rel=1e-2)       # the low-pass keeps a reach's bulge
    # left of the recorded direction stays left of the reach's x–y direction
    assert reach[0] * sideways[1] - reach[1] * sideways[0] > 0


def _tracked_reach(chord, up, side: float, rise: float, origin=(0.1, 0.2, 0.3)) -> Recording:
    """A 3-D reach like _synthetic_recording's along chord (3,) m, at rest for 0.1 s, bulging side (m) along
    up × chord and rise (m) along chord × (up × chord) mid-way."""
    step = 0.005
    t = np.arange(0.0, 0.6 + step / 2, step)
    s = np.clip((t - 0.1) / 0.5, 0.0, 1.0)
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    chord, up = np.asarray(chord, dtype=float), np.asarray(up, dtype=float)
    across = np.cross(up, chord)
    across /= np.linalg.norm(across)
    upward = np.cross(chord, across)
    upward /= np.linalg.norm(upward)
    bump = np.sin(np.pi * s)
    position = np.asarray(origin) + np.outer(progress, chord) + np.outer(side * bump, across) + np.outer(rise * bump, upward)
    return Recording(name="tracked", t=t, position=position, velocity=np.gradient(position, step, axis=0), onset=0.1,
                     end_time=0.6)


def test_a_3d_recorded_path_keeps_its_timing_and_its_scaled_deviations_sideways_and_upward():
    up = np.array([0.0, 1.0, 0.0])                              # a tracker whose y axis points up
    recording = _tracked_reach([-0.06, 0.01, -0.2], up, side=0.01, rise=0.03)
    start, goal = np.array([0.31, 0.0, 0.47]), np.array([0.45, 0.15, 0.20])
    t, position = recorded_reach(recording, start, goal, up)
    assert t[0] == 0.0 and t[-1] == pytest.approx(PLAYBACK_LEAD + 0.5 + END_HOLD)
    np.testing.assert_allclose(position[0], start, atol=1e-12)
    np.testing.assert_allclose(position[-1], goal, atol=1e-12)
    reach = goal - start
    scale = np.linalg.norm(reach) / np.linalg.norm(recording.position[-1] - recording.position[0])
    across = np.cross([0.0, 0.0, 1.0], reach)
    across /= np.linalg.norm(across)
    upward = np.cross(reach, across) / np.linalg.norm(reach)
    assert upward[2] > 0
    # the progress along the chord keeps the recording's normalised timing (to the low-pass's smoothing)
    recorded_progress = (recording.position - recording.position[0]) @ (recording.position[-1] - recording.position[0])
    recorded_progress /= recorded_progress[-1]
    progress = (position - start) @ reach / (reach @ reach)
    np.testing.assert_allclose(progress, np.interp(t + 0.1 - PLAYBACK_LEAD, recording.t, recorded_progress), atol=5e-3)
    middle = int(np.argmin(np.abs(t - (PLAYBACK_LEAD + 0.25))))
    offset = position[middle] - (start + 0.5 * reach)
    assert offset @ across == pytest.approx(0.01 * scale, rel=1e-2)      # sideways stays horizontal, scaled (to the low-pass)
    assert offset @ upward == pytest.approx(0.03 * scale, rel=1e-2)      # upward stays upward, scaled


def test_a_3d_recording_needs_its_up_direction_and_a_planar_one_takes_none():
    start, goal = np.array([0.31, 0.0, 0.47]), np.array([0.45, 0.15, 0.20])
    with pytest.raises(ValueError, match="up"):
        recorded_reach(_tracked_reach([0.2, 0.0, 0.0], [0.0, 0.0, 1.0], 0.0, 0.01), start, goal)
    with pytest.raises(ValueError, match="up"):
        recorded_reach(_synthetic_recording(0.0), start, goal, up=[0.0, 0.0, 1.0])


def test_a_fingertip_that_stops_on_its_target_is_played_as_a_hand_that_comes_to_rest():
    # a reach at 1 m/s that touches down: from full speed to rest in 20 ms (50 m/s²), then still
    step = 0.004
    t = np.arange(0.0, 0.5 + step / 2, step)
    speed = np.where(t < 0.1, 0.0, np.where(t < 0.3, (t - 0.1) / 0.2, np.clip(1.0 - (t - 0.3) / 0.02, 0.0, 1.0)))
    x = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * step)])
    position = np.column_stack([x, np.zeros_like(x)])
    recording = Recording(name="touch", t=t, position=position, velocity=np.gradient(position, step, axis=0), onset=0.1,
                          end_time=0.32)
    start, goal = np.zeros(3), np.array([x[-1], 0.0, 0.0])
    person = RecordedPerson(recording, PersonParameters(hand_path="recorded", anticipates_inertia=False), start, goal)
    times = np.arange(0.0, person.duration, 0.001)
    acceleration = np.array([np.linalg.norm(person.intended_motion(time)[2]) for time in times])
    assert acceleration.max() < 0.5 * 50.0                  # the touch-down is smoothed, not played as recorded
    _, velocity, _ = person.intended_motion(person.duration - 1e-3)
    assert np.linalg.norm(velocity) < 0.01                 # and the hand has come to rest by the playback's end


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_surface_normal_is_the_plane_of_starts_and_ends_turned_to_where_the_hands_rise(sign):
    normal = np.array([0.2, 0.9, 0.4]) / np.linalg.norm([0.2, 0.9, 0.4])
    in_plane = [np.cross(normal, axis) for axis in ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0])]
    recordings = [_tracked_reach(0.2 * direction / np.linalg.norm(direction), sign * normal, side=0.0, rise=0.03,
                                 origin=0.05 * k * in_plane[1]) for k, direction in enumerate(in_plane + [in_plane[0] + in_plane[1]])]
    np.testing.assert_allclose(surface_normal(recordings), sign * normal, atol=1e-9)


@pytest.mark.skipif(not ARMS.is_dir(), reason="the recorded arm reaches (../shared/data/arm_reaches) are not beside this clone")
def test_recorded_arm_people_play_the_development_arm_reaches_onto_the_reach():
    from comanip.simulation import ScenarioSetup, SyncSettings

    setup = ScenarioSetup(SyncSettings(), arm_reaches=ARMS)
    assert len(setup.arm_recordings) > 100
    start, goal = np.array([0.31, 0.0, 0.47]), np.array([0.35, -0.15, 0.20])
    for seed in range(5):
        recording = setup.recording(seed, "recorded-arm")
        assert recording.position.shape[1] == 3
        t, position = recorded_reach(recording, start, goal, setup.arm_up)
        np.testing.assert_allclose(position[[0, -1]], [start, goal], atol=1e-12)
        chord = goal - start
        height = (position - start) @ np.cross(chord, np.cross([0.0, 0.0, 1.0], chord))
        assert np.mean(height) > 0                                 # the hand rises off the surface, as recorded
    with pytest.raises(ValueError, match="arm_reaches"):
        ScenarioSetup(SyncSettings()).recording(0, "recorded-arm")


def test_a_recorded_person_holds_the_offset_leaves_from_rest_and_stays_at_the_goal():
    start, goal, hold = np.array([0.31, 0.0, 0.47]), np.array([0.45, 0.15, 0.20]), np.array([0.31, 0.0, 0.48])
    parameters = PersonParameters(hand_path="recorded", anticipates_inertia=False, pace=1.3)
    person = RecordedPerson(_synthetic_recording(1.0), parameters, start, goal)
    assert person.duration == pytest.approx(1.3 * (PLAYBACK_LEAD + 0.5 + END_HOLD))
    person.start(hold)
    force = person.force(0.0, start, np.zeros(3))
    np.testing.assert_allclose(person.intended_position, hold, atol=1e-12)
    np.testing.assert_allclose(person.intended_velocity, 0.0, atol=1e-9)
    np.testing.assert_allclose(force, parameters.stiffness * (hold - start), atol=1e-9)     # the holding force
    _, _, acceleration = person.intended_motion(0.0)
    np.testing.assert_allclose(acceleration, 0.0, atol=1e-6)
    person.force(person.duration + 0.3, goal, np.zeros(3))
    np.testing.assert_allclose(person.intended_position, hold + goal - start, atol=1e-9)
    np.testing.assert_allclose(person.intended_velocity, 0.0)


def test_usable_recordings_of_the_development_split_map_onto_a_reach():
    cursory = pytest.importorskip("comanip.recordings").load_cursory
    try:
        recordings = cursory("development", limit=200)
    except ValueError as error:       # the data extra is not installed
        pytest.skip(str(error))
    usable = [recording for recording in recordings if usable_for_reach(recording)]
    assert len(usable) > 20
    start, goal = np.array([0.31, 0.0, 0.47]), np.array([0.35, -0.15, 0.20])
    for recording in usable:
        t, position = recorded_reach(recording, start, goal)
        np.testing.assert_allclose(position[0], start, atol=1e-12)
        np.testing.assert_allclose(position[-1], goal, atol=1e-12)
        step = recording.t[1] - recording.t[0]
        assert t[-1] == pytest.approx(PLAYBACK_LEAD + recording.movement_time + END_HOLD, abs=step)


@pytest.mark.parametrize("bad, message", [({"pace": 0.0}, "pace"), ({"pace": float("nan")}, "pace"),
                                          ({"hand_path": "mouse"}, "hand_path")])
def test_bad_person_kinds_are_rejected(bad, message):
    with pytest.raises(ValueError, match=message):
        PersonParameters(**bad)


@pytest.mark.slow
@pytest.mark.parametrize("person", [PersonParameters(pace=0.7), PersonParameters(pace=1.3), PersonParameters(hand_path="recorded")],
                         ids=["x0.7", "x1.3", "recorded"])
def test_the_sync_scenario_runs_with_people_who_are_not_the_model(person):
    if person.hand_path == "recorded":
        pytest.importorskip("cursory")
    from comanip.simulation import SyncSettings, run_sync

    trial, = run_sync(SyncSettings(goal="near", trials=1, policy="continuous", person=person), progress=False)
    assert trial.metrics["final_error_m"] < 0.01
    assert trial.metrics["goal_error_final_m"] < 0.02
    assert (trial.record.replans > 1) == (person.hand_path == "model")


@pytest.mark.slow
@pytest.mark.skipif(not ARMS.is_dir(), reason="the recorded arm reaches (../shared/data/arm_reaches) are not beside this clone")
def test_the_sync_scenario_runs_with_a_recorded_arm_beside_the_arm_preset_robot():
    from comanip.simulation import ScenarioSetup, SyncSettings, run_sync

    settings = SyncSettings(goal="near", trials=1, policy="continuous", online_preset="arm",
                            person=PersonParameters(hand_path="recorded-arm", pace=2.5))
    trial, = run_sync(settings, ScenarioSetup(settings, arm_reaches=ARMS), progress=False)
    assert trial.estimate.goal.shape == (3,) and trial.record.replans == 0
    assert trial.metrics["final_error_m"] < 0.01
    assert trial.metrics["goal_error_final_m"] < 0.05


def test_a_slower_person_gets_their_horizon_on_their_own_clock():
    from comanip.simulation import ScenarioSetup, SyncSettings

    setup = ScenarioSetup(SyncSettings())
    horizon = setup.model.H * setup.model.h
    assert setup.trial_duration(PersonParameters(pace=1.3)) == pytest.approx(1.3 * horizon)
    assert setup.trial_duration(PersonParameters(pace=0.7)) == pytest.approx(horizon)
    assert ScenarioSetup(SyncSettings(duration=1.5)).trial_duration(PersonParameters(pace=2.0)) == 1.5


def test_past_their_horizon_a_person_holds_their_intention(cartesian_planner):
    horizon = cartesian_planner.model.duration
    parameters = PersonParameters(pace=0.7, motor_noise=False, anticipates_inertia=False)
    person = SimulatedPerson(cartesian_planner, parameters, GOAL, 0.05, np.random.default_rng(0))
    person.start(np.zeros(3))
    for t in np.arange(0.0, 0.7 * horizon, 0.02):
        person.force(t, person.intended_position.copy(), person.intended_velocity.copy())
    plans, held = len(person.plans), person.intended_position.copy()
    for t in 0.7 * horizon + np.array([0.01, 0.3, 1.0]):
        person.force(t, held, np.zeros(3))
        np.testing.assert_array_equal(person.intended_position, held)
        np.testing.assert_array_equal(person.intended_velocity, 0.0)
    assert len(person.plans) == plans
    assert np.linalg.norm(held - GOAL) < 0.02
