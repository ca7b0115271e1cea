"""Replay recorded hand states through the goal node, in-process, and record what it publishes.

The recording is a CSV of timestamped states in the format ``comanip estimate --observations`` reads (header
``t_s, q0.., qdot0..``; for a point mass q is the hand position in m and qdot its velocity in m/s), or a ROS 2
bag of the hand's position read as that command reads it. Row k is
published as a TwistStamped and a PoseStamped stamped ``BASE_STAMP + t_k`` while a /clock message sets the
node's clock (use_sim_time) to the same time, so the node sees the recording's own time whatever the speed:

- ``speed=None`` (lock step, as fast as the node goes): each row waits until the node (in the same process)
  has handled it and has no estimate pending, so every row the node would estimate at its ``estimation_rate`` is
  estimated, reproducibly;
- ``speed=s > 0``: rows go out at s times real time and the node keeps up or skips (s = 1: real time).

After the last row the clock runs on at ``command_rate`` to the end of the handover schedule, so the recorded
equilibrium poses and stiffness cover the whole reach. :class:`Recording` holds everything received and
writes it as CSV files.
"""

from __future__ import annotations

import csv
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from comanip.extras import MissingExtra

try:  # the 'ros' extra; without it, one line naming the extra
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TwistStamped
    from nav_msgs.msg import Path as PathMessage
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import Float64MultiArray
except ModuleNotFoundError as error:
    raise MissingExtra("ros", error.name or "rclpy") from None

from comanip.recordings.hand_states import read_hand_states
from comanip.ros.messages import SCHEDULE_COLUMNS, read_schedule, seconds, stamp_of, status_text, status_values
from comanip.ros.node import GoalNode
from comanip.ros.node_settings import NodeSettings

BASE_STAMP = 1000.0
"""ROS time (s) of the recording's t = 0."""


@dataclass
class Recording:
    """What the node published during a replay (times: ``stamp`` ROS time in s, ``t`` = stamp - BASE_STAMP)."""

    goals: list = field(default_factory=list)
    """(stamp, goal (d,) m, covariance (d, d) m², latency s) of each goal message (one per estimate)."""
    goal_stamps: list = field(default_factory=list)
    """(sec, nanosec) of each goal message's header stamp, as received."""
    paths: dict = field(default_factory=dict)
    """estimate stamp -> predicted path (K, 4): stamp, x, y, z."""
    schedules: list = field(default_factory=list)
    """(T, 9) rows of each distinct schedule received (SCHEDULE_COLUMNS)."""
    commands: list = field(default_factory=list)
    """(stamp, rest position (3,) m, stiffness (6,)) of each equilibrium pose with the stiffness that followed it."""
    statuses: list = field(default_factory=list)
    """(stamp, level, message, values dict) of every status."""
    lost: int = 0
    """Hand poses sent that the node never received (dropped by the middleware's queues when it fell behind)."""
    sent: dict = field(default_factory=dict)
    """pose stamp -> time.perf_counter() when it was published."""
    wall_time: float = 0.0
    """Wall time of the replay (s), from the first row to the last row handled."""

    def write(self, folder: str | Path, d: int) -> list[Path]:
        """goals.csv, prediction.csv (the last predicted path), schedule.csv (the last schedule), commands.csv,
        status.csv in ``folder``; returns their paths."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        axes = "xyz"[:d]
        goal_rows = [[stamp, stamp - BASE_STAMP, *goal, *cov.ravel(), latency] for stamp, goal, cov, latency in self.goals]
        last_path = self.paths[max(self.paths)] if self.paths else np.zeros((0, 4))
        files = {
            "goals.csv": (["stamp_s", "t_s"] + [f"goal_{a}_m" for a in axes] + [f"cov_{a}{b}_m2" for a in axes for b in axes]
                          + ["latency_s"], goal_rows),
            "prediction.csv": (["stamp_s", "t_s", "x_m", "y_m", "z_m"],
                               [[row[0], row[0] - (last_path[0, 0] if len(last_path) else 0.0), *row[1:]] for row in last_path]),
            "schedule.csv": (list(SCHEDULE_COLUMNS), self.schedules[-1].tolist() if self.schedules else []),
            "commands.csv": (["stamp_s", "t_s", "rest_x_m", "rest_y_m", "rest_z_m", "stiffness_x_N_per_m",
                              "stiffness_y_N_per_m", "stiffness_z_N_per_m"],
                             [[stamp, stamp - BASE_STAMP, *rest, *stiffness[:3]] for stamp, rest, stiffness in self.commands]),
            "status.csv": (["stamp_s", "level", "message", "stale", "inputs", "rejected", "skipped", "estimates", "failed",
                            "last_solve_status"],
                           [[stamp, level, text] + [values.get(k, "") for k in ("stale", "inputs", "rejected", "skipped", "estimates",
                                                                                 "failed", "last_solve_status")]
                            for stamp, level, text, values in self.statuses]),
        }
        written = []
        for name, (header, rows) in files.items():
            with open(folder / name, "w", newline="") as f:
                writer = csv.writer(f)
                writer.writerow(header)
                writer.writerows(rows)
            written.append(folder / name)
        return written


def private_domain() -> int:
    """A DDS domain id (100–199) for this process's replays, so that other ROS 2 processes on the machine
    (a running node, another replay) neither see nor disturb them."""
    return 100 + os.getpid() % 100


class Replay:
    """The goal node and a player node on one executor in a private ROS context, on :func:`private_domain`;
    use as a context manager. ``transition_model`` goes to the node (:class:`~comanip.ros.node.GoalNode`)."""

    def __init__(self, settings: NodeSettings, transition_model=None):
        self.settings = settings
        self.context = Context()
        rclpy.init(context=self.context, domain_id=private_domain())
        self.node = GoalNode(settings, transition_model=transition_model, use_sim_time=True, context=self.context)
        self.player = Node("comanip_replay", context=self.context)
        self.recording = Recording()
        s, player = settings, self.player
        self._clock = player.create_publisher(Clock, "/clock", 10)
        self._pose = player.create_publisher(PoseStamped, s.hand_pose_topic, 50)
        self._twist = player.create_publisher(TwistStamped, s.hand_twist_topic, 50)
        player.create_subscription(PoseWithCovarianceStamped, s.goal_topic, self._on_goal, 50)
        player.create_subscription(PathMessage, s.path_topic, self._on_path, 50)
        player.create_subscription(Float64MultiArray, s.schedule_topic, self._on_schedule, 50)
        player.create_subscription(PoseStamped, s.equilibrium_topic, self._on_equilibrium, 50)
        player.create_subscription(Float64MultiArray, s.stiffness_topic, self._on_stiffness, 50)
        player.create_subscription(DiagnosticArray, s.status_topic, self._on_status, 50)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.executor.add_node(self.player)
        self._pending_rest = None

    def __enter__(self) -> "Replay":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.player.destroy_node()
        self.context.try_shutdown()

    # ---- recording
    def _on_goal(self, message: PoseWithCovarianceStamped) -> None:
        stamp = seconds(message.header.stamp)
        self.recording.goal_stamps.append((message.header.stamp.sec, message.header.stamp.nanosec))
        d = self.node._d
        p = message.pose.pose.position
        covariance = np.asarray(message.pose.covariance).reshape(6, 6)[:d, :d]
        sent = self.recording.sent.get(stamp)
        latency = float("nan") if sent is None else time.perf_counter() - sent
        self.recording.goals.append((stamp, np.array([p.x, p.y, p.z])[:d], covariance, latency))

    def _on_path(self, message: PathMessage) -> None:
        rows = np.array([[seconds(p.header.stamp), p.pose.position.x, p.pose.position.y, p.pose.position.z] for p in message.poses])
        self.recording.paths[seconds(message.header.stamp) if not rows.size else rows[-1, 0]] = rows

    def _on_schedule(self, message: Float64MultiArray) -> None:
        rows = read_schedule(message)
        if not self.recording.schedules or not np.array_equal(rows, self.recording.schedules[-1]):
            self.recording.schedules.append(rows)

    def _on_equilibrium(self, message: PoseStamped) -> None:
        p = message.pose.position
        self._pending_rest = (seconds(message.header.stamp), np.array([p.x, p.y, p.z]))

    def _on_stiffness(self, message: Float64MultiArray) -> None:
        if self._pending_rest is not None:
            self.recording.commands.append((*self._pending_rest, np.asarray(message.data)))
            self._pending_rest = None

    def _on_status(self, message: DiagnosticArray) -> None:
        status = message.status[0]
        self.recording.statuses.append((seconds(message.header.stamp), int.from_bytes(status.level, "little"), status.message,
                                        status_values(message)))

    # ---- playing
    def set_clock(self, t: float) -> None:
        """Set the node's clock to BASE_STAMP + t (s)."""
        self._clock.publish(Clock(clock=stamp_of(BASE_STAMP + t)))
        self.executor.spin_once(timeout_sec=0.0)

    def drain(self, seconds: float) -> None:
        """Handle callbacks for ``seconds`` of wall time (each spin handles one)."""
        end = time.perf_counter() + seconds
        while time.perf_counter() < end:
            self.executor.spin_once(timeout_sec=0.001)

    def publish(self, t: float, position, velocity, *, frame_id: str | None = None, twist: bool = True, stamp=None) -> None:
        """Publish the twist (unless ``twist`` is False) and the pose of the hand at t (s after BASE_STAMP): position
        (3,) m, velocity (3,) m/s; ``stamp``: the messages' header stamp (a builtin_interfaces/Time) instead."""
        frame = self.settings.frame_id if frame_id is None else frame_id
        stamp = stamp_of(BASE_STAMP + t) if stamp is None else stamp
        position, velocity = np.zeros(3) + np.r_[position, np.zeros(3 - len(position))], np.r_[velocity, np.zeros(3 - len(velocity))]
        if twist:
            message = TwistStamped()
            message.header.stamp, message.header.frame_id = stamp, frame
            message.twist.linear.x, message.twist.linear.y, message.twist.linear.z = (float(v) for v in velocity)
            self._twist.publish(message)
        message = PoseStamped()
        message.header.stamp, message.header.frame_id = stamp, frame
        message.pose.position.x, message.pose.position.y, message.pose.position.z = (float(v) for v in position)
        message.pose.orientation.w = 1.0
        self.recording.sent[seconds(stamp)] = time.perf_counter()
        self._pose.publish(message)

    def wait_handled(self, poses: int, timeout: float = 30.0) -> dict:
        """Spin until the node has handled ``poses`` hand poses and has no estimate pending; its status values
        (as the status message carries them, strings)."""
        deadline = time.perf_counter() + timeout
        while time.perf_counter() < deadline:
            self.executor.spin_once(timeout_sec=0.001)
            _, values = self.node.status()
            if values["inputs"] >= poses and not values["pending"]:
                self.drain(0.005)  # what the node published on the way out
                return {key: status_text(value) for key, value in self.node.status()[1].items()}
        raise TimeoutError(f"the node did not handle {poses} hand poses within {timeout:g} s")

    def wait_idle(self, quiet: float = 0.2, timeout: float = 30.0) -> None:
        """Spin until the node has no estimate pending and has handled no new pose for ``quiet`` seconds (when
        it cannot keep up, the middleware drops messages beyond its queues: they never come)."""
        deadline, seen, since = time.perf_counter() + timeout, -1, time.perf_counter()
        while time.perf_counter() < deadline:
            self.executor.spin_once(timeout_sec=0.001)
            values = self.node.status()[1]
            if values["inputs"] != seen or values["pending"]:
                seen, since = values["inputs"], time.perf_counter()
            elif time.perf_counter() - since > quiet:
                return
        raise TimeoutError(f"the node was still busy after {timeout:g} s")

    def run(self, times, states, speed: float | None = None) -> Recording:
        """Replay states (K, 2d) [x; xdot] at times (K,) s (module docstring); returns the recording."""
        d = self.node._d
        begin = time.perf_counter()
        for k, (t, state) in enumerate(zip(times, states)):
            if speed is not None:
                while (wait := begin + t / speed - time.perf_counter()) > 0:
                    self.executor.spin_once(timeout_sec=wait)
            self.set_clock(t)
            self.publish(t, state[:d], state[d:2 * d])
            if speed is None:
                self.wait_handled(k + 1)
            else:
                self.executor.spin_once(timeout_sec=0.0)
        if speed is None:
            self.wait_handled(len(times))
        else:
            self.wait_idle()
        self.recording.wall_time = time.perf_counter() - begin
        self.recording.lost = len(times) - self.node.status()[1]["inputs"]
        end = max([times[-1]] + [rows[-1, 1] for rows in self.recording.schedules[-1:]])
        for t in np.arange(times[-1], end + 1.0 / self.settings.command_rate, 1.0 / self.settings.command_rate):
            self.set_clock(float(t))
            self.drain(0.002)
        self.drain(0.05)
        return self.recording


def replay_csv(settings: NodeSettings, observations: str | Path, out: str | Path, speed: float | None = None,
               transition_model=None, check_units: bool = True, topic: str | None = None,
               frame: str | None = None) -> tuple[Recording, list[Path]]:
    """Replay a CSV of hand states (``comanip estimate`` format), or a ROS 2 bag of the hand's position (its
    ``topic`` and ``frame``: :func:`comanip.recordings.hand_states.read_hand_states`), through the node; write the
    recording to ``out``. ``check_units`` refuses times that look like ms and positions like mm (or angles like
    degrees)."""
    model = settings.model()
    times, states = read_hand_states(Path(observations), model.n, check_units=check_units, joint_angles=not model.body.is_linear,
                                     name="replay", topic=topic, frame=frame)
    with Replay(settings, transition_model) as replay:
        recording = replay.run(times, states, speed)
    return recording, recording.write(out, model.d)
