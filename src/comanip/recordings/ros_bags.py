"""ROS 2 bags of a tracked hand read as recordings, with the pure-Python ``rosbags`` library (the ``bags`` extra;
no ROS installation).

A bag is a folder with ``metadata.yaml`` and its storage file, or the storage file alone: MCAP (``.mcap``) or
sqlite3 (``.db3``). One topic of it holds the hand's position, as one of

- ``geometry_msgs/msg/PoseStamped`` (``pose.position``) or ``geometry_msgs/msg/PointStamped`` (``point``): the
  messages' ``header.frame_id`` is the frame of the positions;
- ``geometry_msgs/msg/TransformStamped`` (``transform.translation``) or ``tf2_msgs/msg/TFMessage`` (each of its
  transforms): the hand is the transform's ``child_frame_id``, its position given in ``header.frame_id``.

Each sample's time is its ``header.stamp`` (not the time it was recorded at), in s from the first sample; the
samples are sorted by stamp, and positions are read in m (ROS's unit; ``check_units`` refuses positions that
look like mm, :mod:`comanip.units`). ``axes`` keeps the coordinates a model uses ("xy" for a planar one).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from comanip.extras import require
from comanip.recordings.preprocessing import STEP, recording_from_samples
from comanip.recordings.recording import Recording
from comanip.units import check_positions_m

POSITION_TYPES = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PointStamped")
"""the message types a hand topic may have"""
TRANSFORM_TYPES = ("geometry_msgs/msg/TransformStamped", "tf2_msgs/msg/TFMessage")
HAND_TYPES = POSITION_TYPES + TRANSFORM_TYPES
BAG_SUFFIXES = (".mcap", ".db3")
"""suffixes of a bag's storage file"""


def is_bag(path: str | Path) -> bool:
    """True for a bag: a ``.mcap`` or ``.db3`` file, or a folder holding ``metadata.yaml``."""
    path = Path(path)
    return path.suffix in BAG_SUFFIXES or (path.is_dir() and (path / "metadata.yaml").is_file())


def bag_samples(path: str | Path, topic: str | None = None, *, frame: str | None = None, axes: str = "xyz",
                check_units: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The hand's samples in a bag (module docstring): times (N,) s from the first sample, sorted, and positions
    (N, len(axes)) m.

    Args:
        path: the bag (folder or storage file).
        topic: the hand's topic; None: the bag's only topic of a type in :data:`HAND_TYPES`.
        frame: for poses and points, the frame the positions must be given in; for transforms, the hand's
            ``child_frame_id``. None: the only frame the topic has.
        axes: the coordinates kept, in order, from "xyz".
        check_units: refuse positions that look like mm.

    Raises:
        ValueError: (one line) for a path that is no bag, a topic that is missing, of another type or empty,
            samples in several frames without ``frame``, a frame the topic does not have, or positions in mm.
        comanip.extras.MissingExtra: without the ``bags`` extra.
    """
    path = Path(path)
    if not path.exists():
        raise ValueError(f"bag {str(path)!r} does not exist")
    if not axes or set(axes) - set("xyz") or len(set(axes)) != len(axes):
        raise ValueError(f"axes must be distinct letters of 'xyz', e.g. 'xy', got {axes!r}")
    highlevel = require("rosbags.highlevel", "bags")
    typesys = require("rosbags.typesys", "bags")
    try:
        with highlevel.AnyReader([path], default_typestore=typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)) as reader:
            connection = _hand_connection(reader.connections, topic, path)
            samples = [sample for _, _, raw in reader.messages(connections=[connection])
                       for sample in _samples(reader.deserialize(raw, connection.msgtype), connection.msgtype)]
    except ValueError:
        raise
    except Exception as error:  # rosbags' own errors: a file that is no bag, a broken or unknown storage
        raise ValueError(f"could not read bag {str(path)!r}: {type(error).__name__}: {error}") from None
    where = f"bag {str(path)!r}, topic {connection.topic!r}"
    samples = _in_frame(samples, frame, connection.msgtype in TRANSFORM_TYPES, where)
    if len(samples) < 2:
        raise ValueError(f"{where} holds {len(samples)} hand samples; a recording needs at least 2")
    stamps = np.array([stamp for stamp, _, _ in samples], dtype=np.int64)   # ns: a wall-clock stamp in float s loses µs
    positions = np.array([position for _, _, position in samples])[:, ["xyz".index(a) for a in axes]]
    order = np.argsort(stamps, kind="stable")
    t, positions = 1e-9 * (stamps[order] - stamps[order[0]]), positions[order]
    if t[-1] <= 0:
        raise ValueError(f"{where}: every header stamp is the same; comanip times samples by their header stamps")
    if not np.all(np.isfinite(positions)):
        raise ValueError(f"{where} holds NaN or inf positions")
    if check_units:
        check_positions_m(positions, where)
    return t, positions


def read_bag(path: str | Path, topic: str | None = None, *, frame: str | None = None, axes: str = "xyz",
             step: float = STEP, width: float | None = None, target=None, check_units: bool = True) -> Recording:
    """The hand's movement in a bag as a :class:`Recording` (resampled, smoothed, with its onset and end,
    :func:`comanip.recordings.recording_from_samples`), named after the bag. ``topic``, ``frame``, ``axes`` and
    ``check_units``: :func:`bag_samples`; ``step``, ``width`` and ``target`` (len(axes),) m: as for
    :func:`~comanip.recordings.recording_from_samples`."""
    t, positions = bag_samples(path, topic, frame=frame, axes=axes, check_units=check_units)
    return recording_from_samples(bag_name(path), t, positions, step=step, width=width, target=target)


def bag_name(path: str | Path) -> str:
    """A bag's name: its folder's, or its storage file's without the suffix."""
    path = Path(path)
    return path.stem if path.suffix in BAG_SUFFIXES else path.name


def bag_observations(path: str | Path, d: int, topic: str | None = None, *, frame: str | None = None,
                     check_units: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Observed hand states of the movement in a bag, as an observations CSV holds them: times (K,) s from the
    movement's onset (the first row is the onset, t = 0) and states (K, 2d) [position m; velocity m/s] of the
    first d of x, y, z, from :func:`read_bag`."""
    return read_bag(path, topic, frame=frame, axes="xyz"[:d], check_units=check_units).states_from_onset()


def _hand_connection(connections, topic: str | None, path: Path):
    """The connection of the hand's topic (one line ValueError naming the usable topics otherwise)."""
    usable = {c.topic: c for c in connections if c.msgtype in HAND_TYPES}
    listing = ", ".join(f"{c.topic} ({c.msgtype})" for c in connections) or "none"
    if topic is None:
        if len(usable) != 1:
            raise ValueError(f"bag {str(path)!r} has {len(usable)} topics of a hand type ({', '.join(HAND_TYPES)}); "
                             f"name one with topic (--topic); its topics: {listing}")
        return next(iter(usable.values()))
    matching = [c for c in connections if c.topic == topic]
    if not matching:
        raise ValueError(f"bag {str(path)!r} has no topic {topic!r}; its topics: {listing}")
    if topic not in usable:
        raise ValueError(f"topic {topic!r} of bag {str(path)!r} is {matching[0].msgtype}; a hand topic is one of "
                         f"{', '.join(HAND_TYPES)}")
    return usable[topic]


def _samples(message, msgtype: str) -> list[tuple[int, str, tuple[float, float, float]]]:
    """(stamp ns, frame, position (x, y, z) m) of each hand sample in a message: its frame is the header's for a
    pose or point, the child frame for a transform."""
    if msgtype == "tf2_msgs/msg/TFMessage":
        return [sample for transform in message.transforms for sample in _samples(transform, TRANSFORM_TYPES[0])]
    stamp = message.header.stamp.sec * 1_000_000_000 + message.header.stamp.nanosec
    if msgtype == TRANSFORM_TYPES[0]:
        frame, point = message.child_frame_id, message.transform.translation
    else:
        frame, point = message.header.frame_id, message.pose.position if msgtype == POSITION_TYPES[0] else message.point
    return [(stamp, frame, (point.x, point.y, point.z))]


def _in_frame(samples: list, frame: str | None, transform: bool, where: str) -> list:
    """The samples of ``frame``, or all when they share one frame (``frame`` None)."""
    frames = sorted({sample_frame for _, sample_frame, _ in samples})
    kind = "child frame" if transform else "frame"
    if frame is None:
        if len(frames) > 1:
            raise ValueError(f"{where} has samples in the {kind}s {frames}; choose one with frame (--frame)")
        return samples
    if frame not in frames:
        raise ValueError(f"{where} has no samples in the {kind} {frame!r}; its {kind}s: {frames}")
    return [sample for sample in samples if sample[1] == frame]
