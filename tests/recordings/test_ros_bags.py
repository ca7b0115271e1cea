"""ROS 2 bags as recordings: bags the tests write with rosbags' own writer (MCAP and sqlite3; poses, points,
transforms and tf messages, written out of stamp order beside another topic) read back as the samples written,
and the commands give from a bag what they give from the same samples in a CSV."""

import csv
import importlib.util
import json

import numpy as np
import pytest

import comanip
from comanip.cli.main import main
from comanip.recordings.trial_files import load_recordings
from comanip.recordings import read_bag, recording_from_samples
from comanip.recordings.ros_bags import bag_observations, bag_samples, is_bag

rosbags = pytest.importorskip("rosbags", reason="ROS 2 bags need the 'bags' extra: pip install -e '.[bags]'")
from rosbags.rosbag2 import StoragePlugin, Writer  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

TYPES = get_typestore(Stores.ROS2_HUMBLE)
STORAGES = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}
STAMP0 = 1_700_000_000_250_000_000          # ns: a wall-clock header stamp, as a recorder gives


def hand_samples(d: int = 2, goal=(0.3, 0.1)):
    """A planar (or Cartesian) planned reach sampled at 100 Hz after 0.2 s at rest: times (N,) s, positions (N, 3) m
    (z = 0.05 for a planar one)."""
    model = comanip.presets.planar() if d == 2 else comanip.presets.cartesian()
    plan = comanip.Planner(model).solve(np.zeros(2 * d), goal, 0.02)
    t = np.arange(0.0, 0.2 + plan.t[-1], 0.01)
    moving = np.column_stack([np.interp(t - 0.2, plan.t, column, left=0.0) for column in plan.ee_mean.T])
    position = np.column_stack([moving, np.full(len(t), 0.05)]) if d == 2 else moving
    return t, position


def _stamp(t: float):
    sec, nanosec = divmod(STAMP0 + int(round(t * 1e9)), 1_000_000_000)
    return TYPES.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)


def _message(kind: str, t: float, p, frame: str = "world", child: str = "hand"):
    T = TYPES.types
    header = T["std_msgs/msg/Header"](stamp=_stamp(t), frame_id=frame)
    x, y, z = (float(v) for v in p)
    if kind == "PoseStamped":
        pose = T["geometry_msgs/msg/Pose"](position=T["geometry_msgs/msg/Point"](x=x, y=y, z=z),
                                           orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0))
        return T["geometry_msgs/msg/PoseStamped"](header=header, pose=pose)
    if kind == "PointStamped":
        return T["geometry_msgs/msg/PointStamped"](header=header, point=T["geometry_msgs/msg/Point"](x=x, y=y, z=z))
    transform = T["geometry_msgs/msg/TransformStamped"](
        header=header, child_frame_id=child,
        transform=T["geometry_msgs/msg/Transform"](translation=T["geometry_msgs/msg/Vector3"](x=x, y=y, z=z),
                                                   rotation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)))
    if kind == "TransformStamped":
        return transform
    elbow = T["geometry_msgs/msg/TransformStamped"](header=header, child_frame_id="elbow", transform=transform.transform)
    return T["tf2_msgs/msg/TFMessage"](transforms=[elbow, transform])


def write_bag(path, t, position, storage: str = "mcap", kind: str = "PoseStamped", topic: str = "/hand", frames=("world",)):
    """A bag of the samples on ``topic`` (messages written in a shuffled order; recorded times in that order) and
    a string topic beside it; with several ``frames``, each sample once in each (positions + 1 m in the others)."""
    msgtype = "tf2_msgs/msg/TFMessage" if kind == "TFMessage" else f"geometry_msgs/msg/{kind}"
    order = np.random.default_rng(0).permutation(len(t))
    with Writer(path, version=9, storage_plugin=STORAGES[storage]) as writer:
        hand = writer.add_connection(topic, msgtype, typestore=TYPES)
        note = writer.add_connection("/note", "std_msgs/msg/String", typestore=TYPES)
        writer.write(note, 1, TYPES.serialize_cdr(TYPES.types["std_msgs/msg/String"](data="trial 1"), "std_msgs/msg/String"))
        for k, i in enumerate(order):
            for j, frame in enumerate(frames):
                message = _message(kind, t[i], position[i] + j, frame=frame if kind in ("PoseStamped", "PointStamped") else "world",
                                   child="hand" if j == 0 else frame)
                writer.write(hand, 10 + k, TYPES.serialize_cdr(message, msgtype))
    return path


@pytest.mark.parametrize("storage", STORAGES)
@pytest.mark.parametrize("kind", ["PoseStamped", "PointStamped", "TransformStamped", "TFMessage"])
def test_a_bag_reads_back_as_the_samples_written(tmp_path, storage, kind):
    t, position = hand_samples()
    bag = write_bag(tmp_path / "reach", t, position, storage, kind)
    assert is_bag(bag) and not is_bag(tmp_path)
    frame = "hand" if kind == "TFMessage" else None          # the tf message also holds the elbow
    read_t, read_position = bag_samples(bag, frame=frame)
    np.testing.assert_allclose(read_t, t, atol=2e-9)           # header stamps, sorted, from the first
    np.testing.assert_array_equal(read_position, position)
    recording = read_bag(bag, frame=frame, axes="xy")
    expected = recording_from_samples("reach", t, position[:, :2])
    assert recording.name == "reach" and recording.onset == pytest.approx(expected.onset)
    np.testing.assert_allclose(recording.position, expected.position, atol=1e-12)
    np.testing.assert_allclose(recording.velocity, expected.velocity, atol=1e-9)
    storage_file = next(bag.glob("*.mcap" if storage == "mcap" else "*.db3"))
    np.testing.assert_array_equal(bag_samples(storage_file, frame=frame)[1], position)   # the storage file alone


def recordings_csv(t, position) -> str:
    """The rows of a recordings CSV (t, x, y) of the samples, every float written exactly."""
    return "".join(f"{float(ti)!r},{float(x)!r},{float(y)!r}\n" for ti, (x, y, _) in zip(t, position))


def write_observations_csv(path, times, states):
    d = states.shape[1] // 2
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["t_s"] + [f"q{k}" for k in range(d)] + [f"qdot{k}" for k in range(d)])
        writer.writerows([[repr(float(t)), *map(repr, map(float, state))] for t, state in zip(times, states)])
    return path


@pytest.mark.parametrize("storage", STORAGES)
def test_estimate_gives_from_a_bag_what_it_gives_from_the_same_samples_in_a_csv(tmp_path, storage, capsys):
    t, position = hand_samples()
    bag = write_bag(tmp_path / "reach", t, position, storage)
    recording = recording_from_samples("reach", t, position[:, :2])
    keep = recording.t >= recording.onset - 1e-9
    states = np.hstack([recording.position, recording.velocity])[keep]
    table = write_observations_csv(tmp_path / "reach.csv", recording.t[keep] - recording.onset, states)
    times, bag_states = bag_observations(bag, 2)
    np.testing.assert_allclose(bag_states, states, atol=1e-9)
    goals = {}
    for name, source in {"bag": bag, "csv": table}.items():
        out = tmp_path / f"out_{name}"
        assert main(["estimate", "--observations", str(source), "--t-obs", "0.2", "--out", str(out)]) == 0
        goals[name] = json.loads((out / "estimate.json").read_text())["goal"]
    capsys.readouterr()
    np.testing.assert_allclose(goals["bag"], goals["csv"], atol=1e-7)
    assert np.linalg.norm(np.subtract(goals["bag"], [0.3, 0.1])) < 0.05     # and the estimate finds the reach's goal


def test_fit_reads_a_bag_as_one_trial_with_its_goal_from_the_trials_table(tmp_path):
    t, position = hand_samples()
    bag = write_bag(tmp_path / "reach", t, position, "sqlite3")
    trials = tmp_path / "trials.csv"
    trials.write_text("trial,goal_x,goal_y,width\nreach,0.3,0.1,0.02\n")
    table = tmp_path / "reach.csv"
    table.write_text("t,x,y\n" + recordings_csv(t, position))
    [from_bag], [from_csv] = load_recordings(bag, trials), load_recordings(table, trials)
    assert from_bag.name == from_csv.name == "reach" and from_bag.width == from_csv.width
    np.testing.assert_allclose(from_bag.t, from_csv.t, atol=2e-9)
    np.testing.assert_array_equal(from_bag.position, from_csv.position)
    np.testing.assert_array_equal(from_bag.goal, from_csv.goal)
    with pytest.raises(ValueError, match="give a trials table"):
        load_recordings(bag)
    with pytest.raises(ValueError, match="is not a bag"):
        load_recordings(table, trials, topic="/hand")


@pytest.mark.slow
def test_the_fit_command_gives_from_a_bag_what_it_gives_from_the_csv(tmp_path, capsys):
    t, position = hand_samples()
    bag = write_bag(tmp_path / "reach", t, position, "mcap")
    (tmp_path / "trials.csv").write_text("trial,goal_x,goal_y,width\nreach,0.3,0.1,0.02\n")
    (tmp_path / "csv").mkdir()
    (tmp_path / "csv" / "reach.csv").write_text("t,x,y\n" + recordings_csv(t, position))
    fits = {}
    for name, source in {"bag": bag, "csv": tmp_path / "csv"}.items():
        out = tmp_path / f"fit_{name}"
        assert main(["fit", "--recordings", str(source), "--trials", str(tmp_path / "trials.csv"), "--parameters", "kappa",
                     "--max-evaluations", "12", "--out", str(out), "--no-progress"]) in (0, 1)
        fits[name] = json.loads((out / "fit.json").read_text())
    capsys.readouterr()
    assert fits["bag"]["values"]["kappa"] == pytest.approx(fits["csv"]["values"]["kappa"], rel=1e-9)   # times differ by 1e-17 s
    assert fits["bag"]["objective"] == pytest.approx(fits["csv"]["objective"], rel=1e-9)


@pytest.mark.skipif(importlib.util.find_spec("rclpy") is None, reason="the ROS 2 node needs the 'ros' extra")
def test_ros_replay_of_a_bag_publishes_what_the_csv_replay_does(tmp_path, capsys):
    t, position = hand_samples(d=3, goal=(0.35, 0.1, 0.05))
    bag = write_bag(tmp_path / "reach", t, position, "mcap", "TransformStamped")
    times, states = bag_observations(bag, 3)
    table = write_observations_csv(tmp_path / "reach.csv", times, states)
    goals = {}
    for name, source in {"bag": bag, "csv": table}.items():
        out = tmp_path / f"ros_{name}"
        assert main(["ros", "--replay", str(source), "--out", str(out), "--verbose"]) == 0
        goals[name] = json.loads(capsys.readouterr().out)["last_goal_m"]
    np.testing.assert_allclose(goals["bag"], goals["csv"], atol=1e-9)


def test_bad_bags_and_choices_give_one_line(tmp_path, capsys):
    t, position = hand_samples()
    two_frames = write_bag(tmp_path / "frames", t, position, "mcap", "PoseStamped", frames=("world", "camera"))
    with pytest.raises(ValueError, match=r"frames \['camera', 'world'\]; choose one"):
        bag_samples(two_frames)
    np.testing.assert_array_equal(bag_samples(two_frames, frame="camera")[1], position + 1)
    with pytest.raises(ValueError, match="no samples in the frame 'base'"):
        bag_samples(two_frames, frame="base")
    with pytest.raises(ValueError, match="no topic '/wrist'; its topics: /hand"):
        bag_samples(two_frames, "/wrist")
    with pytest.raises(ValueError, match="'/note' of bag .* is std_msgs/msg/String"):
        bag_samples(two_frames, "/note")
    in_mm = write_bag(tmp_path / "mm", t, 1000 * position, "sqlite3")
    with pytest.raises(ValueError, match="look like millimetres"):
        bag_samples(in_mm)
    not_a_bag = tmp_path / "broken.mcap"
    not_a_bag.write_text("no bag")
    with pytest.raises(ValueError, match="could not read bag"):
        bag_samples(not_a_bag)
    for argv, fragment in [(["estimate", "--observations", str(two_frames)], "choose one with frame (--frame)"),
                           (["estimate", "--observations", str(not_a_bag)], "could not read bag"),
                           (["estimate", "--observations", str(in_mm), "--topic", "/hand"], "look like millimetres"),
                           (["estimate", "--preset", "franka", "--observations", str(in_mm)], "q are joint angles")]:
        assert main([*argv, "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and fragment in err[0], err
