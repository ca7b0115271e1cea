"""Simulated people who are not the model: a person at another pace, a person whose intended path is a recording."""

import numpy as np
import pytest

from comanip.recordings.recording import Recording
from comanip.simulation.person import PersonParameters, SimulatedPerson
from comanip.simulation.recorded_person import PLAYBACK_LEAD, RecordedPerson, recorded_reach, usable_for_reach

GOAL = np.array([0.30, 0.10, -0.15])


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
    assert t[0] == 0.0 and t[-1] == pytest.approx(PLAYBACK_LEAD + 0.5)
    np.testing.assert_allclose(position[0], start, atol=1e-12)
    np.testing.assert_allclose(position[-1], goal, atol=1e-12)
    # mid-movement the bulge is sideways, horizontal and scaled by the reach's distance over the recording's
    reach = goal - start
    middle = int(np.argmin(np.abs(t - (PLAYBACK_LEAD + 0.25))))
    offset = position[middle] - (start + 0.5 * reach)
    scale = np.linalg.norm(reach) / 0.2
    np.testing.assert_allclose(offset @ reach, 0.0, atol=1e-9)
    assert offset[2] == pytest.approx(0.0, abs=1e-12)
    assert np.linalg.norm(offset) == pytest.approx(0.02 * scale, rel=1e-9)
    # left of the recorded direction stays left of the reach's x–y direction
    assert reach[0] * offset[1] - reach[1] * offset[0] > 0


def test_a_recorded_person_holds_the_offset_leaves_from_rest_and_stays_at_the_goal():
    start, goal, hold = np.array([0.31, 0.0, 0.47]), np.array([0.45, 0.15, 0.20]), np.array([0.31, 0.0, 0.48])
    parameters = PersonParameters(hand_path="recorded", anticipates_inertia=False, pace=1.3)
    person = RecordedPerson(_synthetic_recording(1.0), parameters, start, goal)
    assert person.duration == pytest.approx(1.3 * (PLAYBACK_LEAD + 0.5))
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
        assert t[-1] == pytest.approx(min(recording.onset, PLAYBACK_LEAD) + recording.movement_time)


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
