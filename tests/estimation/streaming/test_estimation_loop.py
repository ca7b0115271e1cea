"""The loop core without ROS: a stream of several reaches gives as many reaches and estimator restarts, a position
without its velocity is never used, the due times keep the rate, a reach begins with its lead, the newest due
sample replaces an older one, and the loop run as the ROS node runs it estimates what ReachStream estimates."""

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import comanip
from comanip.estimation import (CalibrationSettings, EstimationLoop, LoopEvent, LoopSettings, PersonCalibration, ReachStream,
                                SegmentationSettings)
from tests.estimation.streaming.test_reach_stream import successive_reaches


class RecordingEstimator:
    """Stands in for an OnlineGoalEstimator: records what the loop asks of it, in order."""

    def __init__(self, d: int = 3):
        self.model = SimpleNamespace(state_size=2 * d)
        self.prior_goal = None
        self.calls = []
        self.latest = None

    def reset(self, start, *, prior_goal=None):
        self.calls.append(("reset", np.array(start), prior_goal))

    def update(self, t, position, velocity):
        self.calls.append(("update", t, np.array(position), np.array(velocity)))
        self.latest = t
        return t

    def observe(self, times, positions, velocities):      # observations whose estimates are not read: updates here
        for t, position, velocity in zip(times, positions, velocities):
            self.update(t, position, velocity)

    def finish_reach(self):
        self.calls.append(("finish",))

    def reaches(self) -> list[list[tuple]]:
        """The update calls after each reset."""
        reaches = []
        for call in self.calls:
            if call[0] == "reset":
                reaches.append([])
            elif call[0] == "update":
                reaches[-1].append(call)
        return reaches


def run(loop: EstimationLoop, t, x, v) -> list[LoopEvent]:
    """Paired samples through the loop, every due update run at once (as ReachStream runs them)."""
    events = []
    for k in range(len(t)):
        events.append(loop.add_sample(t[k], x[k], v[k]).event)
        update = loop.take_due()
        if update is not None:
            loop.estimate(update)
    return events


@settings(max_examples=30, deadline=None)
@given(count=st.integers(1, 4), rate=st.sampled_from([100.0, 125.0, 250.0]), rest=st.floats(0.4, 1.0),
       duration=st.floats(0.4, 0.8), seed=st.integers(0, 2**16))
def test_a_stream_of_reaches_gives_as_many_reaches_each_restarting_the_estimator_from_its_rest(count, rate, rest, duration,
                                                                                               seed):
    t, x, v, goals = successive_reaches(count, rate=rate, rest=rest, duration=duration, seed=seed)
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator)
    events = run(loop, t, x, v)
    assert events.count(LoopEvent.STARTED) == events.count(LoopEvent.FINISHED) == count
    assert [c[0] for c in estimator.calls if c[0] != "update"] == ["reset", "finish"] * count
    rests = [np.zeros(3), *goals[:-1]]
    for reset, rested in zip([c for c in estimator.calls if c[0] == "reset"], rests):
        assert np.linalg.norm(reset[1][:3] - rested) < SegmentationSettings().radius and np.all(reset[1][3:] == 0)
    onsets = [rest + k * (rest + duration) for k in range(count)]
    for updates, onset in zip(estimator.reaches(), onsets):
        times = np.array([u[1] for u in updates])
        assert times[0] == 0 and np.all(np.diff(times) > 0)
        assert times[-1] < duration + SegmentationSettings().lead + 0.2     # each reach holds its own samples only
    assert loop.reach.number == count and not loop.under_way and not loop.moving
    assert re.fullmatch(r"(r*sd*f)+r*", "".join({LoopEvent.AT_REST: "r", LoopEvent.STARTED: "s", LoopEvent.DUE: "d",
                                                  LoopEvent.FINISHED: "f"}[e] for e in events))


def test_a_reach_begins_with_its_lead_the_samples_from_its_clock_to_the_one_that_started_it():
    t, x, v, _ = successive_reaches(3, seed=4)
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator)
    clocks = []
    for k in range(len(t)):
        step = loop.add_sample(t[k], x[k], v[k])
        if step.event is LoopEvent.STARTED:
            clocks.append((loop.reach.clock, t[k]))
            lead = [s.stamp for s in step.update.reach.lead]
            assert lead == [s for s in t if loop.reach.clock <= s < t[k]]
            assert 0 < t[k] - loop.reach.clock <= SegmentationSettings().lead + 0.011
        update = loop.take_due()
        if update is not None:
            loop.estimate(update)
    for updates, (clock, started) in zip(estimator.reaches(), clocks):
        stamps = [clock + u[1] for u in updates]
        expected = [s for s in t if clock <= s <= started]
        np.testing.assert_allclose(stamps[:len(expected)], expected, atol=1e-12)   # the lead, then the sample that started it


@settings(max_examples=40, deadline=None)
@given(offsets=st.lists(st.floats(-0.009, 0.009), min_size=30, max_size=60), dropped=st.lists(st.booleans(), min_size=60,
       max_size=60), order=st.lists(st.booleans(), min_size=120, max_size=120))
def test_a_position_without_a_velocity_within_the_tolerance_is_never_used(offsets, dropped, order):
    """Positions every 10 ms, velocities stamped up to 9 ms off them (in stamp order; some never sent), the two
    interleaved in any order: a position is estimated only with a velocity stamped within 5 ms of it."""
    tolerance = 0.005
    stamps = 0.01 * np.arange(len(offsets))
    velocity_stamps = np.sort([s + o for s, o, drop in zip(stamps, offsets, dropped) if not drop])
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator, LoopSettings(pairing_tolerance=tolerance, first_sample_starts_reach=True))
    positions, velocities, decided, choices = list(stamps), list(velocity_stamps), {}, iter(order)
    while positions or velocities:
        if positions and (not velocities or next(choices, True)):
            stamp = positions.pop(0)
            steps = loop.add_position(stamp, [stamp, 0.0, 0.0])      # the position tells its stamp
        else:
            stamp = velocities.pop(0)
            steps = loop.add_velocity(stamp, [stamp, 0.0, 0.0])      # so does the velocity
        for step in steps:
            if step.event is not LoopEvent.WAITING:
                assert step.stamp not in decided
                decided[step.stamp] = step.event
        update = loop.take_due()
        if update is not None:
            loop.estimate(update)
    used = {u[2][0]: u[3][0] for u in estimator.reaches()[0]} if estimator.reaches() else {}
    started = [s for s, e in decided.items() if e is LoopEvent.STARTED]
    for stamp in stamps:
        near = velocity_stamps[np.abs(velocity_stamps - stamp) <= tolerance + 1e-9]
        if stamp in used:
            assert abs(used[stamp] - stamp) <= tolerance + 1e-9
        if near.size == 0:
            assert stamp not in used and stamp not in started
            assert decided.get(stamp, LoopEvent.UNPAIRED) is LoopEvent.UNPAIRED
    assert all(e in (LoopEvent.UNPAIRED, LoopEvent.STARTED, LoopEvent.DUE) for e in decided.values())
    assert len(decided) + loop.waiting == len(stamps)


@settings(max_examples=40, deadline=None)
@given(rate=st.floats(5.0, 60.0), tracker=st.floats(120.0, 500.0), jitter=st.floats(0.0, 0.3), seed=st.integers(0, 2**16))
def test_the_due_times_keep_the_rate_each_a_sample_next_to_its_time_on_the_grid(rate, tracker, jitter, seed):
    """A hand moving on (no rest) from a tracker whose stamps jitter by up to ``jitter`` of half its spacing s: the
    updates come one per 1 / rate of stream time, each the first sample within half its spacing of its due time
    (so within s (1/2 + 3/2 jitter) of it: the one before may have lain just too early)."""
    spacing = 1.0 / tracker
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 2.0, spacing) + np.r_[0.0, rng.uniform(-jitter, jitter, int(np.ceil(2.0 / spacing)) - 1) * spacing / 2]
    x = np.outer(0.3 * t, [1.0, 0.0, 0.0])
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator, LoopSettings(rate=rate, first_sample_starts_reach=True))
    events = run(loop, t, x, np.tile([0.3, 0.0, 0.0], (len(t), 1)))
    due = np.array([u[1] for u in estimator.reaches()[0]])                    # times since the first sample
    grid = np.arange(1, len(due) + 1) / rate
    assert abs(len(due) - math.floor(t[-1] * rate)) <= 1
    assert np.all(np.abs(due - grid) <= spacing * (0.5 + 1.5 * jitter) + 1e-9)
    assert events.count(LoopEvent.DUE) == len(due) and events.count(LoopEvent.NOT_DUE) == len(t) - 1 - len(due)


def test_the_newest_due_update_replaces_one_not_yet_taken():
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator, LoopSettings(first_sample_starts_reach=True))
    for k in range(5):
        loop.add_sample(0.01 * k, [0.01 * k, 0, 0], [1.0, 0, 0])
    assert loop.replaced == 3 and loop.due.sample.stamp == 0.04       # the first sample started the reach
    loop.estimate(loop.take_due())
    assert loop.due is None and loop.take_due() is None
    assert [c[0] for c in estimator.calls] == ["reset", "update"] and estimator.calls[1][1] == pytest.approx(0.04)


def hand(t):
    """At rest at the origin, a 0.2 m reach along x from 0.5 s to 1.0 s, at rest after it: positions (K, 3) m,
    velocities (K, 3) m/s."""
    s = np.clip((t - 0.5) / 0.5, 0, 1)
    x = np.outer(0.2 * (10 * s**3 - 15 * s**4 + 6 * s**5), [1.0, 0.0, 0.0])
    return x, np.outer(0.2 * (30 * s**2 - 60 * s**3 + 30 * s**4) / 0.5, [1.0, 0.0, 0.0])


def test_each_sample_says_what_it_was_for():
    t = np.arange(0.0, 1.6, 0.01)
    x, v = hand(t)
    x[10] = v[10] = np.nan
    loop = EstimationLoop(RecordingEstimator(), LoopSettings(rate=25.0, horizon=0.5))
    events = run(loop, t, x, v)
    assert events[10] is LoopEvent.LOST and set(events[:10]) == {LoopEvent.AT_REST}
    codes = "".join({LoopEvent.AT_REST: "r", LoopEvent.LOST: "l", LoopEvent.STARTED: "s", LoopEvent.DUE: "d",
                     LoopEvent.NOT_DUE: "n", LoopEvent.PAST_HORIZON: "h", LoopEvent.FINISHED: "f"}[e] for e in events)
    assert re.fullmatch(r"r{10}lr+s(n{3}d)+n*h+fr+", codes), codes
    past = codes.index("h")
    assert t[past] - loop.reach.clock >= 0.5 > t[past - 1] - loop.reach.clock
    with pytest.raises(ValueError, match="increase"):
        loop.add_sample(t[-1], x[-1], v[-1])


def test_a_pose_waits_for_its_velocity_and_one_never_paired_is_not_used():
    loop = EstimationLoop(RecordingEstimator(), LoopSettings(pairing_tolerance=0.005, first_sample_starts_reach=True))
    assert [s.event for s in loop.add_position(0.0, np.zeros(3))] == [LoopEvent.WAITING] and loop.waiting == 1
    assert [(s.event, s.stamp) for s in loop.add_velocity(0.001, np.zeros(3))] == [(LoopEvent.STARTED, 0.0)]
    assert [s.event for s in loop.add_position(0.01, [0.01, 0, 0])] == [LoopEvent.WAITING]
    assert [(s.event, s.stamp) for s in loop.add_velocity(0.02, np.zeros(3))] == [(LoopEvent.UNPAIRED, 0.01)]
    assert loop.waiting == 0 and loop.due is None


def test_a_gap_in_the_input_starts_the_next_reach_at_the_pose_after_it():
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator, LoopSettings(restart_after=0.25, first_sample_starts_reach=True))
    t = np.r_[np.arange(0.0, 0.5, 0.01), np.arange(1.0, 1.5, 0.01)]
    events = run(loop, t, np.outer(0.3 * t, [1.0, 0, 0]), np.tile([0.3, 0, 0], (len(t), 1)))
    assert [k for k, e in enumerate(events) if e is LoopEvent.STARTED] == [0, 50]
    assert loop.reach.number == 2 and loop.reach.clock == 1.0
    np.testing.assert_allclose([c[1][0] for c in estimator.calls if c[0] == "reset"], [0.0, 0.3])


def three_reaches():
    """Three minimum-jerk reaches of 0.3 m, each after 0.6 s at rest, from one 100 Hz tracker with 0.5 mm noise:
    times (K,) s, positions (K, 3) m, velocities (K, 3) m/s (a 30 ms backward difference), and the goals."""
    rng = np.random.default_rng(1)
    goals, position, t, x = [], np.zeros(3), [], []
    for direction in ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, -1.0, 0.0]):
        goal = position + 0.3 * np.array(direction) / np.linalg.norm(direction)
        for k in range(120):
            s = max(k - 60, 0) / 60
            t.append(len(t) * 0.01), x.append(position + (goal - position) * (10 * s**3 - 15 * s**4 + 6 * s**5))
        position = goal
        goals.append(goal)
    for k in range(60):
        t.append(len(t) * 0.01), x.append(position.copy())
    x = np.array(x) + rng.normal(0, 5e-4, (len(t), 3))
    return np.array(t), x, np.r_[np.zeros((3, 3)), (x[3:] - x[:-3]) / 0.03], goals


def test_the_loop_fed_as_the_ros_node_feeds_it_estimates_what_reach_stream_estimates():
    """Poses and velocities arriving apart, the first pose starting a reach, every pose due: from the second
    reach on (the first begins at the first pose here, where the hand leaves its rest in ReachStream) the goals
    are ReachStream's, sample for sample. The times jitter, as a tracker's do: with samples exactly a rest window
    apart, rounding would decide whether the hand rests."""
    t, x, v, _ = three_reaches()
    t = t + np.random.default_rng(2).uniform(0, 1e-3, len(t))
    no_learning = dict(person=PersonCalibration(CalibrationSettings(learns=False)))
    stream = ReachStream(comanip.presets.arm(), **no_learning)
    model = comanip.presets.arm()
    loop = EstimationLoop(comanip.OnlineGoalEstimator(model, np.zeros(model.state_size), **no_learning),
                          LoopSettings(rate=1000.0, first_sample_starts_reach=True, horizon=model.H * model.h))
    compared = 0
    for k in range(len(t)):
        expected = stream.update(t[k], x[k], v[k])
        loop.add_velocity(t[k], v[k])
        loop.add_position(t[k], x[k])
        update = loop.take_due()
        estimate = None if update is None else loop.estimate(update)
        if expected.moving and expected.reach >= 2:
            assert loop.reach.number == expected.reach and loop.reach.clock == expected.reach_start
            np.testing.assert_array_equal(estimate.goal, expected.estimate.goal)
            compared += 1
    assert compared > 60


def test_a_first_reach_begun_at_the_first_sample_whose_hand_leaves_only_past_the_horizon_starts_the_next_there():
    """The first sample starts a reach; the hand rests longer than the horizon, then reaches: that reach is
    estimated (a reach of its own, from its lead), not left past the first one's horizon."""
    t = np.arange(0.0, 2.0, 0.01)
    x, v = hand(t - 0.5)                                          # leaves its rest at 1.0 s
    estimator = RecordingEstimator()
    loop = EstimationLoop(estimator, LoopSettings(horizon=0.5, first_sample_starts_reach=True))
    events = run(loop, t, x, v)
    assert [k for k, e in enumerate(events) if e is LoopEvent.STARTED][0] == 0
    assert LoopEvent.PAST_HORIZON in events and loop.reach.number == 2 and 0.8 < loop.reach.clock < 1.0
    assert len(estimator.reaches()[1]) > 30 and LoopEvent.FINISHED in events
