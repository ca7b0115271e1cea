"""Between ROS 2 messages and comanip's arrays: reading checked inputs, building the node's outputs.

Inputs are read into :class:`Sample` (a stamp in s and a (d,) vector in the node's frame) or rejected with a
:class:`RejectedMessage` saying why (NaN or inf, another frame, a stamp not after the previous one), which the
node logs; nothing here raises anything else on a malformed message.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.extras import MissingExtra

try:  # the 'ros' extra; without it, one line naming the extra
    from builtin_interfaces.msg import Time
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
    from geometry_msgs.msg import Pose, PoseStamped, PoseWithCovarianceStamped
    from nav_msgs.msg import Path
    from std_msgs.msg import Float64MultiArray, MultiArrayDimension
except ModuleNotFoundError as error:
    raise MissingExtra("ros", error.name or "rclpy") from None

from comanip.multicomponent.handover import HandoverSchedule
from comanip.estimation.online.online_estimate import OnlineEstimate

#: columns of the schedule message, one row per sample (stamp_s is the ROS time of the sample)
SCHEDULE_COLUMNS = ("stamp_s", "t_s", "rest_x_m", "rest_y_m", "rest_z_m", "rest_vx_m_per_s", "rest_vy_m_per_s",
                    "rest_vz_m_per_s", "stiffness_N_per_m")


class RejectedMessage(ValueError):
    """An input message the node refuses; its text is the log line."""


@dataclass(frozen=True)
class Sample:
    """One checked input: ``stamp`` (s, ROS time), ``vector`` (d,) (m or m/s) and the message's own stamp
    (``header_stamp``, exact: an answer to it carries it back unchanged)."""

    stamp: float
    vector: np.ndarray
    header_stamp: Time


def seconds(stamp: Time) -> float:
    """A builtin_interfaces/Time as seconds (float)."""
    return stamp.sec + 1e-9 * stamp.nanosec


def stamp_of(time_s: float) -> Time:
    """Seconds as a builtin_interfaces/Time (rounded to the nanosecond)."""
    nanoseconds = int(round(time_s * 1e9))
    return Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000)


def read_vector(kind: str, header, xyz, d: int, frame_id: str, previous_stamp: float | None) -> Sample:
    """The first d of (x, y, z) of an input stamped ``header`` (a planar model reads x, y), checked: frame ``frame_id``, finite values,
    a stamp after ``previous_stamp`` (s). ``kind`` names the input in the RejectedMessage."""
    if header.frame_id != frame_id:
        raise RejectedMessage(f"{kind} rejected: frame {header.frame_id!r} is not the node's frame {frame_id!r}")
    stamp = seconds(header.stamp)
    values = np.array([xyz.x, xyz.y, xyz.z], dtype=float)
    if not np.all(np.isfinite(values)):
        raise RejectedMessage(f"{kind} rejected: non-finite values {values.tolist()} at stamp {stamp:.6f} s")
    if previous_stamp is not None and not stamp > previous_stamp:
        raise RejectedMessage(f"{kind} rejected: stamp {stamp:.6f} s is not after the previous one, {previous_stamp:.6f} s")
    return Sample(stamp, values[:d], header.stamp)


def pose_of(position, orientation=(0.0, 0.0, 0.0, 1.0)) -> Pose:
    """A Pose at ``position`` (d ≤ 3,) m, z = 0 when d = 2, with ``orientation`` (x, y, z, w)."""
    pose = Pose()
    xyz = np.zeros(3)
    xyz[: len(position)] = position
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in xyz)
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = (float(v) for v in orientation)
    return pose


def goal_message(goal, covariance, stamp: Time, frame_id: str) -> PoseWithCovarianceStamped:
    """g_hat (d,) m with its covariance (d, d) m² in the position block of the 6×6 pose covariance, stamped ``stamp``
    (the pose it answers); the orientation is unknown (variance -1 on its diagonal, the ROS convention for 'not
    estimated')."""
    message = PoseWithCovarianceStamped()
    message.header.stamp, message.header.frame_id = stamp, frame_id
    message.pose.pose = pose_of(goal)
    full = np.zeros((6, 6))
    d = len(goal)
    full[:d, :d] = covariance
    full[3, 3] = full[4, 4] = full[5, 5] = -1.0
    message.pose.covariance = full.ravel().tolist()
    return message


def path_message(estimate: OnlineEstimate, start_stamp: float, frame_id: str) -> Path:
    """The estimate's path of the hand, ``estimate.path.position`` (K+1, d) m, each pose stamped start_stamp + t_i."""
    message = Path()
    message.header.stamp, message.header.frame_id = stamp_of(start_stamp), frame_id
    for t, position in zip(estimate.path.t, estimate.path.position):
        pose = PoseStamped()
        pose.header.stamp, pose.header.frame_id = stamp_of(start_stamp + float(t)), frame_id
        pose.pose = pose_of(position)
        message.poses.append(pose)
    return message


def schedule_message(schedule: HandoverSchedule, start_stamp: float) -> Float64MultiArray:
    """The schedule as a (T, 9) row-major array with SCHEDULE_COLUMNS (3-D rest position and velocity, zero-padded)."""
    rows = np.zeros((len(schedule.t), len(SCHEDULE_COLUMNS)))
    d = schedule.rest_position.shape[1]
    rows[:, 0] = start_stamp + schedule.t
    rows[:, 1] = schedule.t
    rows[:, 2:2 + d] = schedule.rest_position
    rows[:, 5:5 + d] = schedule.rest_velocity
    rows[:, 8] = schedule.stiffness
    message = Float64MultiArray()
    message.layout.dim = [MultiArrayDimension(label="samples", size=rows.shape[0], stride=rows.size),
                          MultiArrayDimension(label=",".join(SCHEDULE_COLUMNS), size=rows.shape[1], stride=rows.shape[1])]
    message.data = rows.ravel().tolist()
    return message


def read_schedule(message: Float64MultiArray) -> np.ndarray:
    """The (T, 9) rows of a schedule message (columns SCHEDULE_COLUMNS)."""
    return np.asarray(message.data, dtype=float).reshape(message.layout.dim[0].size, message.layout.dim[1].size)


def status_message(level: bytes, text: str, values: dict, stamp: float) -> DiagnosticArray:
    """One DiagnosticStatus named 'comanip goal node' (``level`` DiagnosticStatus.OK/WARN/ERROR, ``text``,
    ``values`` as strings)."""
    array = DiagnosticArray()
    array.header.stamp = stamp_of(stamp)
    status = DiagnosticStatus(level=level, name="comanip goal node", message=text, hardware_id="")
    status.values = [KeyValue(key=str(k), value=status_text(v)) for k, v in values.items()]
    array.status = [status]
    return array


def status_values(message: DiagnosticArray) -> dict:
    """The key/value pairs of a status message, as strings."""
    return {kv.key: kv.value for kv in message.status[0].values}


def status_text(value) -> str:
    """A status value as the message carries it: floats exactly (the shortest text that reads back as the same
    number: a stamp keeps its nanoseconds), booleans as 'true'/'false'."""
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return str(value).lower() if isinstance(value, bool) else str(value)
