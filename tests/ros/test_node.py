"""The ROS 2 goal node in-process (no robot, no ROS installation): a planned reach replayed through it gives
the library's own estimates, predictions and handover schedule; bad messages are logged and rejected; an
estimate over its budget or a silent input leaves the last good estimate published and marked stale."""

import numpy as np
import pytest

rclpy = pytest.importorskip("rclpy", reason="the ROS 2 node needs the 'ros' extra: pip install -e '.[test,ros]'")

from geometry_msgs.msg import PointStamped  # noqa: E402

import comanip  # noqa: E402
from comanip.estimation.model_reaches.model_families import FamilyCache  # noqa: E402
from comanip.estimation.model_reaches.estimation_planner import estimation_planner  # noqa: E402
from comanip.multicomponent.handover import plan_handover  # noqa: E402
from comanip.estimation import CalibrationSettings, PersonCalibration  # noqa: E402
from comanip.multicomponent.transition_model import TransitionModel  # noqa: E402
from comanip.ros.replay import BASE_STAMP, Replay, replay_csv  # noqa: E402
from comanip.ros.node_settings import NodeSettings  # noqa: E402
from tests.estimation.streaming.test_estimation_loop import three_reaches  # noqa: E402

GOAL = np.array([0.4, 0.25, -0.1])


@pytest.fixture(scope="module")
def reach():
    """The Cartesian model's plan from rest at the origin to GOAL: the synthetic hand."""
    settings = NodeSettings()
    planner = estimation_planner(settings.model())
    return settings, planner, planner.solve(np.zeros(6), GOAL)


@pytest.fixture(scope="module")
def transition():
    return TransitionModel()


@pytest.fixture(scope="module")
def replayed(reach, transition, tmp_path_factory):
    """The reach written as a CSV in the format `comanip estimate` reads, replayed through the node in lock step."""
    settings, _, plan = reach
    path = tmp_path_factory.mktemp("ros") / "hand.csv"
    header = "t_s,q0,q1,q2,qdot0,qdot1,qdot2"
    np.savetxt(path, np.c_[plan.t, plan.mean], delimiter=",", header=header, comments="")
    recording, files = replay_csv(settings, path, path.parent / "out", transition_model=transition)
    return recording, files


@pytest.fixture(scope="module")
def library(reach):
    """What the library gives for the same observations fed to the same estimator in the same order."""
    settings, planner, plan = reach
    estimator = settings.online_settings().estimator(plan.mean[0], model=planner, cache=FamilyCache())
    horizon = plan.t[-1]
    estimates = [estimator.update(t, s[:3], s[3:]) for t, s in zip(plan.t[1:], plan.mean[1:]) if t < horizon]
    return [(t, e) for t, e in zip(plan.t[1:], estimates) if e.success]


def test_the_published_estimates_are_the_librarys(replayed, library):
    recording, _ = replayed
    assert len(recording.goals) == len(library) > 40
    for (stamp, goal, covariance, _), (t, estimate) in zip(recording.goals, library):
        assert stamp - BASE_STAMP == pytest.approx(t, abs=1e-9)
        np.testing.assert_allclose(goal, estimate.goal, atol=1e-9)
        np.testing.assert_allclose(covariance, estimate.goal_covariance, atol=1e-12)
    # exact observations of a plan give its goal back (to the reach family's interpolation, ~1e-4 m or less)
    np.testing.assert_allclose(recording.goals[-1][1], GOAL, atol=1e-4)


def test_the_published_prediction_and_schedule_are_the_librarys(reach, replayed, library, transition):
    settings, _, plan = reach
    recording, _ = replayed
    last = library[-1][1]
    path = recording.paths[max(recording.paths)]
    np.testing.assert_allclose(path[:, 0] - BASE_STAMP, last.path.t, atol=1e-6)  # the forecast, stamped in ns
    np.testing.assert_allclose(path[:, 1:], last.path.position, atol=1e-9)
    assert last.path.t[0] == pytest.approx(library[-1][0]) and last.path.t[-1] == pytest.approx(last.forecast.stop_time)
    schedule = plan_handover(last, transition, ramp_time=settings.ramp_time, leading_stiffness=settings.leading_stiffness)
    rows = recording.schedules[-1]
    np.testing.assert_allclose(rows[:, 1], schedule.t, atol=1e-9)
    np.testing.assert_allclose(rows[:, 2:5], schedule.rest_position, atol=1e-9)
    np.testing.assert_allclose(rows[:, 8], schedule.stiffness, atol=1e-9)
    # the hand hands over where its forecast comes within the transition distance, now at the latest
    assert schedule.status in ("within_plan", "at_start") and last.path.t[0] <= schedule.transition_time < last.path.t[-1]
    assert (schedule.status == "at_start") == (np.linalg.norm(last.path.position[0] - last.goal) <= schedule.transition_distance)


def test_the_commands_sample_a_published_schedule_at_the_nodes_clock(reach, replayed):
    settings, _, _ = reach
    recording, _ = replayed
    assert len(recording.commands) > 40
    errors = []
    for stamp, rest, stiffness in recording.commands:
        t = stamp - BASE_STAMP
        sampled = [np.r_[[np.interp(t, rows[:, 1], rows[:, k]) for k in (2, 3, 4, 8)]] for rows in recording.schedules]
        # stamps carry ns: a path and a steep stiffness ramp read a few ns apart (m; N/m)
        errors.append(min(max(np.max(np.abs(rest - row[:3])) / 1e-6, abs(stiffness[0] - row[3]) / 1e-3) for row in sampled))
        np.testing.assert_allclose(stiffness[:3], stiffness[0])
        np.testing.assert_allclose(stiffness[3:], settings.rotational_stiffness)
    # most commands are a recorded schedule sampled; one whose schedule the recorder did not keep (a worker that
    # fell behind under load skips observations, so its estimates are not the recorded ones) matches none exactly
    assert np.mean(np.array(errors) < 1) >= 0.75, sorted(errors)[-5:]
    stiffness = np.array([c[2][0] for c in recording.commands])
    assert stiffness[0] == settings.leading_stiffness and stiffness[-1] == 0.0  # the robot led, then handed over


def test_the_replay_writes_what_was_published(replayed):
    recording, files = replayed
    assert {f.name for f in files} == {"goals.csv", "prediction.csv", "schedule.csv", "commands.csv", "status.csv"}
    goals = np.genfromtxt(files[0], delimiter=",", names=True)
    np.testing.assert_allclose(goals["goal_x_m"][-1], recording.goals[-1][1][0])
    assert np.all(goals["latency_s"] > 0)


def test_a_jittering_tracker_gets_the_configured_estimation_rate(reach, transition):
    """Poses from a 100 Hz tracker whose stamps jitter by up to ±3 ms, at estimation_rate 20 Hz: the estimates lie
    on the rate's grid of due times (the pose nearest each), 20 a second of input time, and the status says so.
    A rule of one period since the last estimated pose gives about 17 a second here."""
    settings, _, plan = reach
    rng = np.random.default_rng(0)
    times = np.arange(0.0, 2.0, 0.01) + np.r_[0.0, rng.uniform(-0.003, 0.003, 199)]
    states = np.column_stack([np.interp(times, plan.t, plan.mean[:, k]) for k in range(6)])
    with Replay(NodeSettings(estimation_rate=20.0), transition) as replay:
        recording = replay.run(times, states, None)
        status = replay.node.status()[1]
    stamps = np.array([stamp for stamp, *_ in recording.goals])
    assert len(stamps) > 20                    # until the hand rests near its goal (about 1.4 s): then the reach is over
    assert (len(stamps) - 1) / (stamps[-1] - stamps[0]) == pytest.approx(20.0, abs=0.3)
    assert np.all(np.abs(np.diff(stamps) - 0.05) < 0.02)  # each the pose nearest its due time: within 8 ms of it
    assert status["achieved_rate_hz"] == pytest.approx(20.0, abs=0.3) and status["configured_rate_hz"] == 20.0
    assert status["latency_median_s"] > 0


def test_bad_messages_are_rejected_with_a_log_line_and_the_node_goes_on(reach, transition, capfd):
    settings, _, plan = reach
    nan = np.full(3, np.nan)
    with Replay(settings, transition) as replay:
        poses = 0

        def send(k, position=None, velocity=None, *, t=None, frame=None, handled=True):
            nonlocal poses
            t = plan.t[k] if t is None else t
            replay.set_clock(t)
            replay.publish(t, plan.mean[k, :3] if position is None else position, plan.mean[k, 3:] if velocity is None else velocity,
                           frame_id=frame)
            poses += 1
            if handled:
                replay.wait_handled(poses)

        prior = replay.player.create_publisher(PointStamped, settings.prior_goal_topic, 10)
        for frame in ("camera", settings.frame_id):            # a prior in another frame, then a good one
            message = PointStamped()
            message.header.frame_id, (message.point.x, message.point.y, message.point.z) = frame, GOAL.tolist()
            prior.publish(message)
            replay.drain(0.2)
        assert replay.node.status()[1]["last_event"] == f"prior goal {GOAL.tolist()} m, for the next reach"
        for k in range(6):
            send(k)
        assert np.array_equal(replay.node.loop.reach.prior_goal, GOAL)
        send(6, position=nan)                          # a NaN position (its twist is fine)
        send(6, frame="camera")                        # another frame: pose and twist
        send(4)                                        # stamps before the last accepted pose and twist
        send(6, velocity=nan, t=plan.t[6] + 0.01, handled=False)   # a NaN twist: its pose finds no twist
        replay.drain(0.05)                             # read before the next pose replaces it (the node keeps one unread)
        for k in range(7, len(plan.t)):
            send(k)
        values = replay.recording.statuses[-1][3]
        goal = replay.recording.goals[-1][1]
    log = capfd.readouterr().err
    assert int(values["rejected"]) == 8
    for line in ("prior goal rejected: frame 'camera'", "hand pose rejected: non-finite values", "hand pose rejected: frame 'camera' is not the node's frame 'world'",
                 "hand twist rejected: frame 'camera'", "hand pose rejected: stamp 1000.220000 s is not after the previous one",
                 "hand twist rejected: non-finite values", "hand pose rejected: no hand twist within 0.005 s of its stamp 1000.340000 s"):
        assert line in log
    np.testing.assert_allclose(goal, GOAL, atol=1e-4)  # and it went on estimating


def test_stale_when_input_stops_the_status_says_so_and_no_old_estimate_is_sent_again(reach, transition):
    settings, _, plan = reach
    with Replay(settings, transition) as replay:
        for k in range(12):
            replay.set_clock(plan.t[k])
            replay.publish(plan.t[k], plan.mean[k, :3], plan.mean[k, 3:])
            values = replay.wait_handled(k + 1)
        assert values["stale"] == "false" and int(values["estimates"]) > 0
        goals, statuses = len(replay.recording.goals), len(replay.recording.statuses)
        for t in np.arange(plan.t[11], plan.t[11] + 1.0, 0.02):  # the clock runs on, the hand is not seen
            replay.set_clock(float(t))
            replay.drain(0.005)
        replay.drain(0.1)
        level, values = replay.recording.statuses[-1][1], replay.recording.statuses[-1][3]
        assert values["stale"] == "true" and values["stale_reason"].startswith("no input for more than") and level == 1
        # the status goes on at status_rate with the last estimate's goal; the goal topic carries new estimates only
        assert len(replay.recording.statuses) >= statuses + 5 and len(replay.recording.goals) == goals
        np.testing.assert_allclose(np.array(values["goal_m"].strip("[]").split(","), dtype=float), replay.recording.goals[-1][1])


def test_stale_when_estimates_overrun_the_budget_and_still_published(reach, transition):
    _, _, plan = reach
    with Replay(NodeSettings(max_wall_time=1e-9), transition) as replay:
        for k in range(8):
            replay.set_clock(plan.t[k])
            replay.publish(plan.t[k], plan.mean[k, :3], plan.mean[k, 3:])
            values = replay.wait_handled(k + 1)
        assert values["stale"] == "true" and values["stale_reason"].startswith("last estimate took")
        assert int(values["late"]) == int(values["estimates"]) == len(replay.recording.goals) > 0


def test_an_uninterrupted_stream_of_reaches_gets_a_reach_number_and_a_goal_each_without_a_reset(transition):
    """Three reaches from one tracker and no reset: the node starts each reach itself, says which is under way,
    and estimates each one's goal."""
    t, x, v, goals = three_reaches()
    with Replay(NodeSettings(preset="arm", estimation_rate=20.0), transition) as replay:
        recording = replay.run(t, np.c_[x, v], None)
    reaches = [int(values["reach"]) for _, _, _, values in recording.statuses]
    assert sorted(set(reaches) - {0}) == [1, 2, 3] and reaches == sorted(reaches)        # 0: before the first pose
    for number, goal in enumerate(goals, start=1):
        # the last estimate published while reach ``number`` was the one under way
        last = max(stamp for stamp, _, _, values in recording.statuses if int(values["reach"]) == number)
        estimate = [g for stamp, g, _, _ in recording.goals if stamp <= last][-1]
        assert np.linalg.norm(estimate - goal) < 0.01, (number, estimate, goal)


def test_a_reach_found_in_the_stream_is_estimated_as_reach_stream_estimates_it(transition):
    """Every pose estimated: the node's goals for the reaches it finds in the stream are ReachStream's, which
    gives each reach's estimator the samples from the reach's start on (those before the pose that started it
    included). The stamps are the sample times to a nanosecond, so the times are jittered: with samples exactly
    a rest window apart, a nanosecond decides whether the hand rests."""
    t, x, v, _ = three_reaches()
    t = t + np.random.default_rng(2).uniform(0, 1e-3, len(t))     # a tracker's jitter: no two samples exactly a window apart
    with Replay(NodeSettings(preset="arm", estimation_rate=1000.0, learn_person=False), transition) as replay:
        recording = replay.run(t, np.c_[x, v], None)
    # the node's first reach begins at its first pose, the stream's where the hand leaves its rest: what each
    # learns of the person from it differs, so both learn nothing here
    stream = comanip.ReachStream(comanip.presets.arm(), person=PersonCalibration(CalibrationSettings(learns=False)))
    library = {}
    for k in range(len(t)):
        latest = stream.update(t[k], x[k], v[k])
        if latest.moving and latest.reach >= 2:
            library[round(t[k], 6)] = latest.estimate.goal
    compared = 0
    for stamp, goal, _, _ in recording.goals:
        expected = library.get(round(stamp - BASE_STAMP, 6))
        if expected is not None:
            np.testing.assert_allclose(goal, expected, atol=1e-9)
            compared += 1
    assert compared > 60


def test_a_tracker_without_twists_is_estimated_from_its_poses_and_each_goal_carries_its_poses_stamp(reach, transition):
    """Poses alone, stamped where a float second cannot hold the nanoseconds (2026's epoch seconds): no pose is
    rejected, the velocity comes from the poses' backward difference, the estimates find the goal, and every goal
    message carries the stamp of a pose sent, to the nanosecond."""
    from builtin_interfaces.msg import Time

    _, _, plan = reach
    times = np.arange(0.0, 1.6, 0.004)
    positions = np.column_stack([np.interp(times, plan.t, plan.mean[:, k]) for k in range(3)])
    sent = [Time(sec=1_765_000_000 + int(t), nanosec=int(round((t % 1) * 1e9)) + 123) for t in times]
    with Replay(NodeSettings(estimation_rate=250.0), transition) as replay:
        for k, (t, position) in enumerate(zip(times, positions)):
            replay.set_clock(t)
            replay.publish(t, position, np.zeros(3), twist=False, stamp=sent[k])
            values = replay.wait_handled(k + 1)
        replay.drain(0.05)
        recording = replay.recording
    assert int(values["rejected"]) == 0 and values["velocity_from"] == "poses"
    assert len(recording.goals) > 100
    assert set(recording.goal_stamps) <= {(stamp.sec, stamp.nanosec) for stamp in sent}
    assert len(set(recording.goal_stamps)) == len(recording.goal_stamps)       # each estimate sent once
    np.testing.assert_allclose(recording.goals[-1][1], GOAL, atol=0.01)


def test_the_handover_schedule_is_rebuilt_at_most_schedule_rate_times_a_second(reach, transition):
    """Every pose of a 200 Hz tracker estimated, the schedule rebuilt on at most 25 of them a second: the schedules
    sent are one per 40 ms of input time (the first estimate's included), and the goals keep coming at the tracker's
    rate."""
    _, _, plan = reach
    times = np.arange(0.0, 1.0, 0.005)
    states = np.column_stack([np.interp(times, plan.t, plan.mean[:, k]) for k in range(6)])
    with Replay(NodeSettings(estimation_rate=400.0, schedule_rate=25.0), transition) as replay:
        recording = replay.run(times, states, None)
    goals = np.array([stamp for stamp, *_ in recording.goals]) - BASE_STAMP
    assert len(goals) > 150
    span = goals[-1] - goals[0]
    assert len(recording.schedules) <= int(span * 25.0) + 2 and len(recording.schedules) >= int(span * 25.0) - 2
