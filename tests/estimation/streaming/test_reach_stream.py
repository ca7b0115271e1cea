"""An uninterrupted stream of successive reaches: every reach found (none merged, none split), each reach's
estimator holding only its own samples, and its goal where the hand comes to rest."""

import numpy as np
import pytest

import comanip
from comanip.estimation import OnlineSettings, ReachStream, SegmentationSettings


def successive_reaches(count: int, rate: float = 100.0, rest: float = 0.5, duration: float = 0.5, noise: float = 5e-4,
                       seed: int = 0):
    """Times (K,) s, positions (K, 3) m with ``noise`` m, backward-difference velocities (K, 3) m/s over 30 ms of
    ``count`` minimum-jerk reaches of 0.15-0.35 m in random directions, each after ``rest`` s at rest; the goals."""
    rng = np.random.default_rng(seed)
    t, x, goals, position, now = [], [], [], np.zeros(3), 0.0
    for _ in range(count):
        for _ in range(int(rest * rate)):
            t.append(now), x.append(position.copy())
            now += 1 / rate
        direction = rng.normal(size=3)
        goal = position + rng.uniform(0.15, 0.35) * direction / np.linalg.norm(direction)
        for k in range(int(duration * rate)):
            s = k / (duration * rate)
            t.append(now), x.append(position + (goal - position) * (10 * s**3 - 15 * s**4 + 6 * s**5))
            now += 1 / rate
        position = goal
        goals.append(goal)
    for _ in range(int(rest * rate)):
        t.append(now), x.append(position.copy())
        now += 1 / rate
    t, x = np.array(t), np.array(x) + rng.normal(0, noise, (len(t), 3))
    back = int(round(0.03 * rate))
    return t, x, np.r_[np.zeros((back, 3)), (x[back:] - x[:-back]) / (back / rate)], np.array(goals)


def test_every_reach_of_a_stream_is_found_with_its_goal_and_no_reach_holds_more_than_its_own_samples():
    t, x, v, goals = successive_reaches(8)
    stream = ReachStream(comanip.presets.arm())
    ends, largest, previous = {}, 0, stream.latest
    for k in range(len(t)):
        latest = stream.update(t[k], x[k], v[k])
        if stream.estimator is not None:
            largest = max(largest, stream.estimator.observation_count)
        if previous.moving and not latest.moving:
            ends[latest.reach] = latest.estimate.goal
        previous = latest
    assert latest.reach == len(goals) and sorted(ends) == list(range(1, len(goals) + 1))
    for number, goal in ends.items():
        assert np.linalg.norm(goal - goals[number - 1]) < SegmentationSettings().radius
    assert largest <= (0.15 + 0.5 + 0.2) * 100                     # lead, the reach, the rest that ends it


def test_a_stream_refuses_time_going_back_and_skips_lost_samples():
    stream = ReachStream(comanip.presets.arm())
    stream.update(0.0, np.zeros(3), np.zeros(3))
    assert stream.update(0.01, [np.nan] * 3, [np.nan] * 3) is stream.latest
    with pytest.raises(ValueError, match="increase"):
        stream.update(0.0, np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError, match="radius"):
        SegmentationSettings(radius=0.0)


def test_bad_estimator_options_are_refused_when_the_stream_is_made():
    with pytest.raises(ValueError, match="width"):
        ReachStream(comanip.presets.arm(), OnlineSettings(model="arm", width=-0.01))


def test_a_stream_learns_the_person_from_every_reach_that_ends_at_rest():
    t, x, v, goals = successive_reaches(4)
    stream = ReachStream(comanip.presets.arm())
    shared = set()
    for k in range(len(t)):
        stream.update(t[k], x[k], v[k])
        if stream.estimator is not None:
            shared.add(stream.estimator.person is stream.person)
    assert stream.person.reaches == len(goals) and stream.estimator is None and shared == {True}
    stream.forget_person()
    assert stream.person.reaches == 0 and stream.person.spread == 1.0
