"""The ROS 2 goal node: online goal estimation, prediction and the handover's impedance schedule, in a robot's loop.

Inputs (topic names are parameters, :class:`~comanip.ros.node_settings.NodeSettings`): the hand's pose and, if the
tracker sends one, its twist, a prior goal, a reset. The node converts each checked message into a sample of an
:class:`~comanip.estimation.streaming.estimation_loop.EstimationLoop`, which does the rest as it does for
:class:`~comanip.estimation.ReachStream`. The hand's velocity (``velocity_source``) is the twist of (nearly) the
same stamp as the pose (``twist_tolerance``), or a backward difference of the poses over ``velocity_window``
(:class:`~comanip.estimation.streaming.derived_velocity.DerivedVelocity`, the rule the recorded people the model is fitted on
were streamed with); by default the poses' until the first twist arrives. A reach starts at the first hand pose
(after startup, a reset, or a gap in the input longer than ``input_timeout``), at rest at that pose's position,
its stamp t = 0; every pose goes to the reach segmenter, and when the hand has rested (within ``rest_radius`` for
``rest_window``) the reach is over (the estimator learns the person from it) and the next one starts when the
hand leaves its rest again, from where it rested, its t = 0 the segmenter's (the rest just before it left); the
status says which reach is under way and whether the hand moves. ``estimation_rate`` poses per second of input
time are due for an estimate, on a grid of 1 / estimation_rate from the reach's start (the pose nearest each due
time), so a tracker whose stamps jitter still gets the configured rate (the tracker's own rate, e.g. 250 Hz,
estimates every pose); poses past the model's horizon, and those at rest between reaches, are not estimated.

The estimates come from :class:`~comanip.estimation.OnlineGoalEstimator` (every observation of the reach so
far, any time) and run in the executor's thread, one at a time: a pose that makes an update due triggers a guard
condition whose callback runs after every input that has arrived is read, so the update runs on the newest due
pose (one interpreter thread: a second would share the interpreter with the first and slow both). The node never
queues: it keeps one unread pose (``INPUT_DEPTH``; a newer one replaces it), and when an estimate takes longer
than the poses' spacing the newest due pose replaces one not yet estimated (counted as skipped), so an estimate
is always of the newest pose, never of a stale one, and the answers thin out instead of falling behind. An estimate is a few
Gauss–Newton steps on a precomputed reach family, not a plan solve, and takes no budget argument: one that takes
longer than ``max_wall_time`` is still published, counted as late, and marks the status stale until one comes in
time. Each successful estimate is published once, at once: g_hat with covariance, stamped exactly with the pose it
answers (the pose message's own stamp), and the predicted hand path; then, at most ``schedule_rate`` times a
second, the handover schedule of :func:`~comanip.multicomponent.handover.plan_handover` on the predicted reach (the
robot's impedance rest position follows the predicted hand, and its stiffness ramps to 0 where the transition
model predicts the person takes over). Every message on the goal topic is a new estimate. Timers publish the
status (``status_rate``; it carries the last good estimate's goal and stamp, and goes out at once after a
rejected input too) and sample the schedule at the node's clock into the equilibrium pose and stiffness
(``command_rate``).

Stale: the status says ``stale: true`` (level WARN) while there is no estimate yet, the last solve failed
or overran ``max_wall_time``, or no input came for ``input_timeout``; the equilibrium pose and stiffness keep
following the last good schedule. The status also reports, over the last ``RATE_WINDOW`` s of input time, the
poses' rate, the estimation rate achieved (every estimate counted, published or not), the share of the poses
estimated, and the latency (from a pose's arrival to the publication of its goal and predicted path, which go out
before the schedule is built on them: the last one, the median and the 95th percentile); it counts the estimates
whose latency exceeded the poses' spacing (``over_period``: the next pose came before the answer), and the poses by
what they were for: estimated, skipped (between due times, or replaced by a newer one), ignored (past the
horizon), resting (between reaches), rejected. Malformed inputs (NaN, another frame, a stamp not after the
previous) are logged and counted, never raised.
"""

from __future__ import annotations

import threading
import time
import warnings
from collections import deque
from dataclasses import dataclass

import numpy as np

from comanip.extras import MissingExtra

try:  # the 'ros' extra; without it, one line naming the extra
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from geometry_msgs.msg import PointStamped, PoseStamped, PoseWithCovarianceStamped, TwistStamped
    from nav_msgs.msg import Path
    import rclpy
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from std_msgs.msg import Empty, Float64MultiArray
except ModuleNotFoundError as error:
    raise MissingExtra("ros", error.name or "rclpy") from None

from comanip.estimation import OnlineEstimate
from comanip.estimation.streaming.derived_velocity import DerivedVelocity
from comanip.estimation.streaming.estimation_loop import LoopEvent, LoopStep, Reach, Update
from comanip.estimation.model_reaches.model_families import FamilyCache
from comanip.estimation.model_reaches.estimation_planner import estimation_planner
from comanip.estimation.estimate_status import EstimateStatus
from comanip.multicomponent.handover import HandoverSchedule, plan_handover
from comanip.multicomponent.transition_model import TransitionModel
from comanip.ros.messages import (RejectedMessage, goal_message, path_message, pose_of, read_vector, schedule_message, stamp_of,
                                  status_message)
from comanip.ros.node_settings import NodeSettings

QUEUE_DEPTH = 50
"""Depth of the publishers' queues and of the subscriptions but the hand's (messages)."""
INPUT_DEPTH = 1
"""Unread hand poses (and twists) the node keeps: a newer one replaces one not yet read, so that no queue of poses
builds up behind a slow estimate."""
RATE_WINDOW = 1.0
"""Input time (s) over which the status's achieved rate and median latency are taken."""
QUIET_PUBLISHER, QUIET_SUBSCRIPTION = (PublisherEventCallbacks(use_default_callbacks=False),
                                      SubscriptionEventCallbacks(use_default_callbacks=False))
"""No QoS-event handlers on the node's topics (each would be visited on every wake of the executor)."""


@dataclass
class GoodEstimate:
    """The last successful estimate, the last schedule built (on it or an estimate before it, ``schedule_rate``), the
    stamps (s) of the pose the estimate answers and of the one whose estimate the schedule was built on."""

    estimate: OnlineEstimate
    schedule: HandoverSchedule
    reach: Reach
    stamp: float
    scheduled: float


class GoalNode(Node):
    """The node; ``settings`` as checked NodeSettings (ROS parameters given with --ros-args override them),
    ``transition_model`` the fitted :class:`TransitionModel` of the handover (None: fit on the shipped data, ~5 s)."""

    def __init__(self, settings: NodeSettings, *, transition_model: TransitionModel | None = None, node_name: str = "comanip_goal",
                 use_sim_time: bool = False, **node_kwargs):
        # every entity of a node is visited on every wake of the executor, in Python: the node has only its own topics
        # and timers (no parameter or type-description services, no QoS-event callbacks)
        super().__init__(node_name, parameter_overrides=[Parameter("use_sim_time", value=use_sim_time),
                                                         Parameter("start_type_description_service", value=False)],
                         start_parameter_services=False, **node_kwargs)
        self._lock = threading.RLock()
        """Held by every callback: the node's state may be read (``status``) from another thread."""
        self.settings = self._declared(settings)
        s = self.settings
        model = s.model()
        self._d = model.d
        self._horizon = model.H * model.h
        self._transition = transition_model if transition_model is not None else TransitionModel()
        prior = None if s.prior_goal is None else np.array(s.prior_goal)
        self.loop = s.online_settings().estimation_loop(prior_goal=prior, model=estimation_planner(model),
                                                        cache=FamilyCache(size=1))
        """The node's loop (:mod:`comanip.estimation.streaming.estimation_loop`): its callbacks feed it under the node's lock,
        the guard condition's callback runs the updates it makes due."""
        self._last_pose: float | None = None
        self._last_twist: float | None = None
        self._derived = DerivedVelocity(s.velocity_window, restart_after=s.input_timeout)
        """The velocity from the poses (``velocity_source`` 'poses', or 'auto' before the first twist)."""
        self._header_stamps: deque = deque(maxlen=QUEUE_DEPTH * 4)
        """(stamp s, the pose message's own stamp) of the recent poses, so that an answer carries its pose's stamp
        exactly."""
        self._poses: deque = deque()
        """Stamps (s) of the poses of the last RATE_WINDOW s of input time."""
        self._last_input_clock: float | None = None
        self._recent: list[tuple[float, float]] = []
        """(input stamp s, latency s or NaN) of the estimates of the last RATE_WINDOW s of input time."""
        self._good: GoodEstimate | None = None
        self._counts = dict(inputs=0, rejected=0, skipped=0, ignored=0, resting=0, estimates=0, failed=0, late=0,
                            over_period=0)
        self._last = dict(solve_ok=True, solve_status="none", solve_time_s=float("nan"), latency_s=float("nan"), rejection="", event="started")

        self._goal_pub = self._publisher(PoseWithCovarianceStamped, s.goal_topic)
        self._path_pub = self._publisher(Path, s.path_topic)
        self._schedule_pub = self._publisher(Float64MultiArray, s.schedule_topic)
        self._equilibrium_pub = self._publisher(PoseStamped, s.equilibrium_topic)
        self._stiffness_pub = self._publisher(Float64MultiArray, s.stiffness_topic)
        self._status_pub = self._publisher(DiagnosticArray, s.status_topic)
        self._subscription(PoseStamped, s.hand_pose_topic, self._on_pose, INPUT_DEPTH)
        self._subscription(TwistStamped, s.hand_twist_topic, self._on_twist, INPUT_DEPTH)
        self._subscription(PointStamped, s.prior_goal_topic, self._on_prior)
        self._subscription(Empty, s.reset_topic, self._on_reset)
        self.create_timer(1.0 / s.command_rate, self._publish_command)
        self.create_timer(1.0 / s.status_rate, self._publish_status)
        self._estimates = self.create_guard_condition(self._run_due)
        """Triggered when an update falls due: its callback runs after every input that has arrived is read."""

    def _publisher(self, message_type, topic: str):
        """A publisher on ``topic`` without QoS-event handlers (:data:`QUIET_PUBLISHER`)."""
        return self.create_publisher(message_type, topic, QUEUE_DEPTH, event_callbacks=QUIET_PUBLISHER)

    def _subscription(self, message_type, topic: str, callback, depth: int = QUEUE_DEPTH) -> None:
        """A subscription to ``topic`` keeping ``depth`` unread messages, without QoS-event handlers
        (:data:`QUIET_SUBSCRIPTION`)."""
        self.create_subscription(message_type, topic, callback, depth, event_callbacks=QUIET_SUBSCRIPTION)

    def _declared(self, settings: NodeSettings) -> NodeSettings:
        """Declare every setting as a ROS parameter and return the settings with the overrides given to the
        node (``--ros-args -p name:=value``) applied, checked again."""
        descriptor = ParameterDescriptor(dynamic_typing=True)
        values = {name: self.declare_parameter(name, value, descriptor).value for name, value in settings.to_mapping().items()}
        return NodeSettings.from_mapping(values)

    # ---- the inputs: checked, fed to the loop
    def now(self) -> float:
        """The node's clock (s): ROS time, or the replay's /clock under use_sim_time."""
        return self.get_clock().now().nanoseconds * 1e-9

    def derives_velocity(self) -> bool:
        """True while the velocity comes from the poses (``velocity_source``)."""
        source = self.settings.velocity_source
        return source == "poses" or (source == "auto" and self._last_twist is None)

    def _on_twist(self, message: TwistStamped) -> None:
        if self.settings.velocity_source == "poses":
            return
        with self._lock:
            try:
                sample = read_vector("hand twist", message.header, message.twist.linear, self._d, self.settings.frame_id, self._last_twist)
            except RejectedMessage as error:
                self._reject(error)
                return
            self._last_twist = sample.stamp
            self._handle(self.loop.add_velocity(sample.stamp, sample.vector))

    def _on_pose(self, message: PoseStamped) -> None:
        received = time.perf_counter()
        with self._lock:
            try:
                sample = read_vector("hand pose", message.header, message.pose.position, self._d, self.settings.frame_id, self._last_pose)
            except RejectedMessage as error:
                self._counts["inputs"] += 1
                self._reject(error)
                return
            self._last_pose = sample.stamp
            self._last_input_clock = self.now()
            self._header_stamps.append((sample.stamp, sample.header_stamp))
            self._poses.append(sample.stamp)
            while self._poses[0] < sample.stamp - RATE_WINDOW:
                self._poses.popleft()
            if self.derives_velocity():
                velocity = self._derived.add(sample.stamp, sample.vector)
                self._handle([self.loop.add_sample(sample.stamp, sample.vector, velocity, received)])
            else:
                self._handle(self.loop.add_position(sample.stamp, sample.vector, received))

    def _handle(self, steps: list[LoopStep]) -> None:
        """Count, log and act on what the loop made of each pose (holding the lock); an update due triggers its run."""
        for step in steps:
            if step.event is LoopEvent.WAITING:
                continue
            self._counts["inputs"] += 1
            if step.event is LoopEvent.UNPAIRED:
                self._reject(RejectedMessage(f"hand pose rejected: no hand twist within {self.settings.twist_tolerance:g} s "
                                             f"of its stamp {step.stamp:.6f} s"))
            elif step.event is LoopEvent.NOT_DUE:
                self._counts["skipped"] += 1
            elif step.event is LoopEvent.AT_REST:
                self._counts["resting"] += 1
            elif step.event is LoopEvent.PAST_HORIZON:
                self._counts["ignored"] += 1
                self._last["event"] = (f"pose at t = {step.stamp - self.loop.reach.clock:.3f} s is past the model's horizon "
                                       f"{self._horizon:g} s; waiting for the hand to rest and start the next reach")
            elif step.event is LoopEvent.STARTED:
                self._recent = []
                self._log_event(f"reach {self.loop.reach.number} started at stamp {self.loop.reach.clock:.6f} s")
            elif step.event is LoopEvent.FINISHED:
                self._log_event(f"reach {self.loop.reach.number} finished: the hand rests at stamp {step.stamp:.6f} s")
        if self.loop.due is not None:
            self._estimates.trigger()

    def _log_event(self, event: str) -> None:
        self._last["event"] = event
        self.get_logger().info(event)

    def _on_prior(self, message: PointStamped) -> None:
        with self._lock:
            try:
                sample = read_vector("prior goal", message.header, message.point, self._d, self.settings.frame_id, None)
            except RejectedMessage as error:
                self._reject(error)
                return
            self.loop.prior_goal = sample.vector
            self._log_event(f"prior goal {sample.vector.tolist()} m, for the next reach")

    def _on_reset(self, _message: Empty) -> None:
        with self._lock:
            self.loop.restart()
            self._derived.restart()
            self._good = None
            self._log_event("reset: the next hand pose starts a reach")

    def _reject(self, error: RejectedMessage) -> None:
        """Count and log a rejected input, and say so in a status at once (called holding the lock)."""
        self._counts["rejected"] += 1
        self._last["rejection"] = str(error)
        self.get_logger().warning(str(error))
        self._publish_status()

    # ---- the estimates: one at a time, on the newest due pose
    def _run_due(self) -> None:
        """The update due, if one still is (a later trigger may find it taken), estimated and published."""
        with self._lock:
            job = self.loop.take_due()
            if job is None:
                return
            latency = float("nan")
            try:
                latency = self._estimate(job)
            except Exception as error:  # noqa: BLE001 - the node must outlive any solver fault; it is logged
                self._last.update(solve_ok=False, solve_status=f"error: {type(error).__name__}: {error}")
                self._counts["failed"] += 1
                self.get_logger().error(f"estimate at t = {job.t:.3f} s raised {type(error).__name__}: {error}")
            if job.sample is not None:
                stamp = job.sample.stamp
                self._recent = [(before, seconds) for before, seconds in self._recent if before > stamp - RATE_WINDOW]
                self._recent.append((stamp, latency))
                if latency > self._input_period():
                    self._counts["over_period"] += 1

    def _estimate(self, job: Update) -> float:
        """Run the update and publish its estimate; returns the latency (s) from the pose's arrival to the
        publication, NaN when nothing was published."""
        s = self.settings
        try:
            estimate = self.loop.estimate(job)
        except ValueError as error:
            self._last["solve_status"] = f"refused: {error}"
            self.get_logger().info(f"observation at t = {job.t:.3f} s not used: {error}")
            return float("nan")
        if job.sample is None:                           # the update only finished its reach
            return float("nan")
        if estimate.status == EstimateStatus.UNINFORMATIVE:  # the hand has not moved yet: nothing to estimate, nothing failed
            self._last.update(solve_status=estimate.status, event=f"waiting for movement at t = {job.t:.3f} s")
            return float("nan")
        ok = bool(estimate.success and np.all(np.isfinite(estimate.goal)) and np.all(np.isfinite(estimate.path.position)))
        self._last.update(solve_ok=ok, solve_status=estimate.status, solve_time_s=estimate.solve_time)
        if estimate.solve_time > s.max_wall_time:
            self._counts["late"] += 1
        if not ok:
            self._counts["failed"] += 1
            self.get_logger().warning(f"estimate at t = {job.t:.3f} s failed ({estimate.status}: {estimate.message}); "
                                      "keeping the last good one, marked stale")
            return float("nan")
        frame, clock = s.frame_id, job.reach.clock   # no callback runs during an update: its reach is the loop's
        self._counts["estimates"] += 1
        self._goal_pub.publish(goal_message(estimate.goal, estimate.goal_covariance, self._header_stamp(job.sample.stamp), frame))
        self._path_pub.publish(path_message(estimate, clock, frame))   # goal and forecast first: the schedule takes longer
        latency = self._last["latency_s"] = time.perf_counter() - job.sample.received
        good = self._good
        if good is not None and good.reach is job.reach and job.sample.stamp - good.scheduled < 1.0 / s.schedule_rate:
            self._good = GoodEstimate(estimate, good.schedule, job.reach, job.sample.stamp, good.scheduled)  # schedule_rate
            return latency
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the transition model's extrapolation warning; its status says so
            schedule = plan_handover(estimate, self._transition, ramp_time=s.ramp_time, leading_stiffness=s.leading_stiffness)
        self._good = GoodEstimate(estimate, schedule, job.reach, job.sample.stamp, job.sample.stamp)
        self._schedule_pub.publish(schedule_message(schedule, clock))
        return latency

    def _header_stamp(self, stamp: float):
        """The pose message's own stamp for the pose stamped ``stamp`` (s), and the older ones forgotten (holding the
        lock); a stamp rounded to the nanosecond for a pose no longer kept."""
        kept = self._header_stamps
        while kept and kept[0][0] < stamp:
            kept.popleft()
        return kept[0][1] if kept and kept[0][0] == stamp else stamp_of(stamp)

    # ---- publishing
    def _publish_command(self) -> None:
        good = self._good
        if good is None:
            return
        now = self.now()
        schedule, t = good.schedule, now - good.reach.clock
        rest = [np.interp(t, schedule.t, schedule.rest_position[:, k]) for k in range(schedule.rest_position.shape[1])]
        stiffness = float(np.interp(t, schedule.t, schedule.stiffness))
        pose = PoseStamped()
        pose.header.stamp, pose.header.frame_id = stamp_of(now), self.settings.frame_id
        pose.pose = pose_of(rest, self.settings.equilibrium_orientation)
        self._equilibrium_pub.publish(pose)
        rotational = self.settings.rotational_stiffness
        self._stiffness_pub.publish(Float64MultiArray(data=[stiffness] * 3 + [rotational] * 3))

    def stale_reason(self) -> str:
        """Why the published estimate is stale ('' when it is fresh)."""
        if self._good is None:
            return "no estimate yet"
        if not self._last["solve_ok"]:
            return f"last solve: {self._last['solve_status']}"
        if self._last["solve_time_s"] > self.settings.max_wall_time:
            return f"last estimate took {self._last['solve_time_s']:.3g} s, over max_wall_time {self.settings.max_wall_time:g} s"
        if self._last_input_clock is not None and self.now() - self._last_input_clock > self.settings.input_timeout:
            return f"no input for more than {self.settings.input_timeout:g} s"
        return ""

    def status(self) -> tuple[str, dict]:
        """(why the estimate is stale, '' when fresh; the status values: counts, last solve, last rejection, ...)."""
        with self._lock:
            reason = self.stale_reason()
            good, reach = self._good, self.loop.reach
            counts = dict(self._counts, skipped=self._counts["skipped"] + self.loop.replaced)
            return reason, dict(stale=bool(reason), stale_reason=reason, **counts,
                                pending=bool(self.loop.due is not None or self.loop.waiting),
                                reach=0 if reach is None else reach.number, moving=self.loop.moving,
                                reach_start_stamp_s=float("nan") if reach is None else reach.clock,
                                estimate_stamp_s=float("nan") if good is None else good.stamp,
                                goal_m=[] if good is None else good.estimate.goal.tolist(),
                                transition_time_s=float("nan") if good is None else good.schedule.transition_time,
                                last_solve_status=self._last["solve_status"], last_solve_time_s=self._last["solve_time_s"],
                                last_latency_s=self._last["latency_s"], **self._achieved(), last_rejection=self._last["rejection"],
                                last_event=self._last["event"])

    def _input_period(self) -> float:
        """The poses' median spacing (s) over the last RATE_WINDOW s of input time (inf until there are two; called
        holding the lock)."""
        return float(np.median(np.diff(self._poses))) if len(self._poses) > 1 else float("inf")

    def _achieved(self) -> dict:
        """Over the last RATE_WINDOW s of input time (called holding the lock; NaN until there are two): the poses'
        rate, the estimates' rate (per second of input time), the share of the poses estimated, and the estimates'
        median and 95th-percentile latency (s)."""
        stamps = [stamp for stamp, _ in self._recent]
        latencies = [seconds for _, seconds in self._recent if not np.isnan(seconds)]
        span = stamps[-1] - stamps[0] if len(stamps) > 1 else 0.0
        poses = self._poses
        input_span = poses[-1] - poses[0] if len(poses) > 1 else 0.0
        return dict(achieved_rate_hz=(len(stamps) - 1) / span if span > 0 else float("nan"),
                    configured_rate_hz=self.settings.estimation_rate,
                    input_rate_hz=(len(poses) - 1) / input_span if input_span > 0 else float("nan"),
                    estimated_share=len([t for t in stamps if t >= poses[0]]) / len(poses) if poses else float("nan"),
                    latency_median_s=float(np.median(latencies)) if latencies else float("nan"),
                    latency_p95_s=float(np.percentile(latencies, 95)) if latencies else float("nan"),
                    velocity_from="poses" if self.derives_velocity() else "twist")

    def _publish_status(self) -> None:
        reason, values = self.status()
        level = DiagnosticStatus.WARN if reason else DiagnosticStatus.OK
        self._status_pub.publish(status_message(level, reason or "estimating", values, self.now()))


def spin(settings: NodeSettings, ros_args: list[str]) -> int:
    """Run the node until Ctrl-C or a ROS shutdown; ``ros_args`` follow ``--ros-args`` (remappings, parameters)."""
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

    rclpy.init(args=["comanip", "--ros-args", *ros_args] if ros_args else None)
    node = None
    try:
        node = GoalNode(settings)
        used = node.settings
        node.get_logger().info(f"estimating from {node.resolve_topic_name(used.hand_pose_topic)} in frame "
                               f"{used.frame_id!r} with the {used.preset!r} model")
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
