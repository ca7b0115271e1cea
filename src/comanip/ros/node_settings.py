"""Settings of the ROS 2 goal node: a frozen dataclass with one documented field per ROS parameter, built
from a YAML file (a flat mapping, or ROS 2's ``node_name: {ros__parameters: {...}}`` layout) and checked at
construction with the library's own validators (:mod:`comanip.arguments`,
:func:`comanip.multicomponent.handover.check_schedule_arguments`), so a bad value is the same one-line
ValueError as on the command line, naming the parameter. Needs no ROS installation.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from pathlib import Path

import yaml

from comanip import presets
from comanip.estimation.hand_rest import REST_RADIUS_M, REST_WINDOW_S
from comanip.estimation.streaming import online_settings
from comanip.estimation.streaming.estimation_loop import LoopSettings
from comanip.estimation.streaming.online_settings import OnlineSettings
from comanip.estimation.streaming.reach_segmentation import SegmentationSettings
from comanip.recordings.motion_capture import VELOCITY_WINDOW_S
from comanip.arguments import as_goal_width, as_nonnegative, as_positive, as_vector
from comanip.bodies.point_mass import PointMass
from comanip.model import ReachingModel
from comanip.multicomponent.handover import DEFAULT_RAMP_TIME, LEADING_STIFFNESS, check_schedule_arguments


VELOCITY_SOURCES = ("auto", "twist", "poses")
"""The values of :attr:`NodeSettings.velocity_source`."""


@dataclass(frozen=True)
class NodeSettings:
    """Everything the node is told (ROS parameters of the same names). Units: m, s, Hz, N/m, N·m/rad."""

    preset: str = "cartesian"
    """Model: a built-in preset name or a model YAML path. Its body must be a point mass (with or without muscle
    activation stages), whose position is the hand's in task space (the Cartesian and arm presets: x, y, z; the
    planar one: x, y)."""
    width: float | None = None
    """Goal width w (m); None: the preset's."""
    prior_goal: tuple[float, ...] | None = None
    """Prior goal g_bar (d,) m until a message on ``prior_goal_topic`` replaces it; None: no prior."""
    frame_id: str = "world"
    """Frame of every input and output; an input in another frame is rejected."""
    hand_pose_topic: str = "hand/pose"
    """geometry_msgs/PoseStamped of the hand (or the co-manipulated object); its position is used."""
    hand_twist_topic: str = "hand/twist"
    """geometry_msgs/TwistStamped of the same; its linear velocity is used."""
    prior_goal_topic: str = "goal/prior"
    """geometry_msgs/PointStamped: the prior goal for the next reach."""
    reset_topic: str = "reset"
    """std_msgs/Empty: the next hand pose starts a new reach."""
    goal_topic: str = "goal/estimate"
    """geometry_msgs/PoseWithCovarianceStamped: g_hat and its covariance (position block, m²)."""
    path_topic: str = "hand/predicted_path"
    """nav_msgs/Path: the predicted hand path from the start to g_hat, stamped on the model's grid."""
    equilibrium_topic: str = "equilibrium_pose"
    """geometry_msgs/PoseStamped: the impedance rest position x_r(now) (the handover schedule sampled)."""
    stiffness_topic: str = "stiffness"
    """std_msgs/Float64MultiArray [Kx, Ky, Kz, Krx, Kry, Krz]: the impedance stiffness at now."""
    schedule_topic: str = "handover/schedule"
    """std_msgs/Float64MultiArray: the whole handover schedule, one row per sample (columns in its layout)."""
    status_topic: str = "status"
    """diagnostic_msgs/DiagnosticArray: stale flag, solve status, counts, last rejection."""
    max_wall_time: float = 0.25
    """Wall-time budget of one estimate (s): one that takes longer is still published but marks the status stale."""
    estimation_rate: float = 20.0
    """Most estimates per second of input time (Hz); hand poses in between are skipped, and so is a due pose that
    a newer one replaces while an estimate runs. The tracker's own rate (e.g. 250) estimates every pose."""
    command_rate: float = 100.0
    """Rate of the equilibrium pose and stiffness (Hz)."""
    schedule_rate: float = 50.0
    """Most handover schedules built per second of input time (Hz): an estimate whose pose comes less than
    1 / schedule_rate after the last schedule's keeps that schedule (building one takes about as long as an
    estimate); the first estimate of a reach always builds one."""
    status_rate: float = 10.0
    """Rate at which the status is republished (Hz); it carries the last good estimate's goal and stamp (the goal and
    path topics carry each estimate once, when it is new)."""
    input_timeout: float = 0.25
    """Input older than this (s) makes the estimate stale; a pose after a longer gap starts a new reach."""
    rest_radius: float = REST_RADIUS_M
    """A hand pose farther than this (m) from where the hand rests starts the next reach; a hand whose poses stay
    within it of their mean for ``rest_window`` rests (:mod:`comanip.estimation.streaming.reach_segmentation`)."""
    rest_window: float = REST_WINDOW_S
    """How long (s) the hand must stay still to rest between reaches."""
    estimator: str = "recorded"
    """The online estimation the node runs: a shipped description's name or a description YAML
    (:func:`comanip.estimation.streaming.online_settings.load`; e.g. "recorded", a person who may not move as the
    model does, or "correcting", the model's own plan with deviations corrected, the simulated scenarios' person).
    The node's own parameters above and below (``preset``, ``width``, ``estimation_rate``, ``rest_radius``, ...)
    replace the description's (:meth:`online_settings`)."""
    learn_person: bool = True
    """Learn the person's amplitude, pace and spread from each finished reach and apply them to the next
    (:mod:`comanip.estimation.calibration.person_calibration`); false: every reach is a person not seen yet."""
    twist_tolerance: float = 0.005
    """Largest stamp difference (s) between a pose and the twist paired with it."""
    velocity_source: str = "auto"
    """Where the hand's velocity comes from (:data:`VELOCITY_SOURCES`): "twist", the twist stamped nearest each pose
    (within ``twist_tolerance``; a pose without one is rejected); "poses", a backward difference of the poses over
    ``velocity_window`` (:mod:`comanip.estimation.streaming.derived_velocity`; twists are ignored); "auto", from the poses until
    the first twist arrives, then from the twists."""
    velocity_window: float = VELOCITY_WINDOW_S
    """Span (s) of the backward difference that derives the velocity from the poses."""
    ramp_time: float = DEFAULT_RAMP_TIME
    """Stiffness ramp to 0 at the handover (s), :func:`comanip.multicomponent.handover.plan_handover`."""
    leading_stiffness: float = LEADING_STIFFNESS
    """Translational stiffness while the robot leads (N/m)."""
    rotational_stiffness: float = 30.0
    """Rotational stiffness sent with it (N·m/rad), constant."""
    equilibrium_orientation: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    """Orientation quaternion (x, y, z, w) of the equilibrium pose (default: a Panda's hand pointing down)."""

    def __post_init__(self):
        for name in ("preset", "frame_id") + TOPICS:
            value = getattr(self, name)
            if not isinstance(value, str) or not value.strip():
                raise ValueError(f"{name} must be a non-empty string, got {value!r}")
        model = self.model()  # the preset's own ValueError, prefixed with the parameter's name
        if not isinstance(getattr(model.body, "inner", model.body), PointMass):    # activation stages allowed
            raise ValueError(f"preset: the node estimates a hand in task space and needs a point-mass model "
                             f"(e.g. 'cartesian' or 'planar'), got the {type(model.body).__name__} body of {self.preset!r}")
        if self.width is not None:
            object.__setattr__(self, "width", as_goal_width("width", self.width))
        if self.prior_goal is not None:
            object.__setattr__(self, "prior_goal", tuple(as_vector("prior_goal", self.prior_goal, model.d, "m").tolist()))
        for name in ("max_wall_time", "estimation_rate", "command_rate", "schedule_rate", "status_rate", "input_timeout", "rotational_stiffness",
                     "rest_radius", "rest_window", "velocity_window"):
            object.__setattr__(self, name, as_positive(name, getattr(self, name), UNITS[name]))
        object.__setattr__(self, "twist_tolerance", as_nonnegative("twist_tolerance", self.twist_tolerance, "s"))
        if self.velocity_source not in VELOCITY_SOURCES:
            raise ValueError(f"velocity_source must be one of {VELOCITY_SOURCES}, got {self.velocity_source!r}")
        try:
            self.online_settings()
        except ValueError as error:
            raise ValueError(f"estimator: {error}") from None
        if not isinstance(self.learn_person, bool):
            raise ValueError(f"learn_person must be true or false, got {self.learn_person!r}")
        check_schedule_arguments(self.ramp_time, self.leading_stiffness, None)
        quaternion = as_vector("equilibrium_orientation", self.equilibrium_orientation, 4, "quaternion x, y, z, w")
        if abs(float(quaternion @ quaternion) - 1.0) > 1e-6:
            raise ValueError(f"equilibrium_orientation must be a unit quaternion (x, y, z, w), got {quaternion.tolist()}")
        object.__setattr__(self, "equilibrium_orientation", tuple(quaternion.tolist()))

    def online_settings(self) -> OnlineSettings:
        """The node's online estimation: the description :attr:`estimator` names, with the node's model, width,
        learning, rate, rest, pairing and restart settings, the model's horizon, and the first pose starting a reach."""
        described = online_settings.load(self.estimator)
        segmentation = described.loop.segmentation or SegmentationSettings()
        model = self.model()
        loop = LoopSettings(dataclasses.replace(segmentation, radius=self.rest_radius, window=self.rest_window),
                            rate=self.estimation_rate, pairing_tolerance=self.twist_tolerance, horizon=model.H * model.h,
                            restart_after=self.input_timeout, first_sample_starts_reach=True)
        return described.replace(model=self.preset, width=self.width, learn_person=self.learn_person, loop=loop)

    def model(self) -> ReachingModel:
        """The model named by ``preset``; a ValueError names the parameter."""
        try:
            return presets.load(self.preset)
        except ValueError as error:
            raise ValueError(f"preset: {error}") from None

    @classmethod
    def from_mapping(cls, values: dict) -> "NodeSettings":
        """Settings from a mapping of parameter names to values; an unknown name is a ValueError listing the known ones."""
        if not isinstance(values, dict):
            raise ValueError(f"the node's parameters must be a mapping of names to values, got a {type(values).__name__}")
        known = [f.name for f in fields(cls)]
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise ValueError(f"unknown parameter(s) {unknown}; the node's parameters are {known}")
        return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in values.items()})

    @classmethod
    def from_yaml(cls, path: str | Path) -> "NodeSettings":
        """Settings from a YAML file: a flat mapping, or ``<node name>: {ros__parameters: {...}}``."""
        path = Path(path)
        try:
            values = yaml.safe_load(path.read_text()) or {}
        except yaml.YAMLError as error:
            raise ValueError(f"--params: {str(path)!r} is not valid YAML: {str(error).splitlines()[0]}") from None
        if isinstance(values, dict) and len(values) == 1:
            (inner,) = values.values()
            if isinstance(inner, dict) and "ros__parameters" in inner:
                values = inner["ros__parameters"] or {}
        return cls.from_mapping(values)

    def to_mapping(self) -> dict:
        """The settings as plain values (tuples as lists), e.g. to declare them as ROS parameters."""
        return {f.name: list(v) if isinstance(v := getattr(self, f.name), tuple) else v for f in fields(self)}


#: the topic-name fields
TOPICS = ("hand_pose_topic", "hand_twist_topic", "prior_goal_topic", "reset_topic", "goal_topic", "path_topic",
          "equilibrium_topic", "stiffness_topic", "schedule_topic", "status_topic")

UNITS = {"max_wall_time": "s", "estimation_rate": "Hz", "command_rate": "Hz", "schedule_rate": "Hz", "status_rate": "Hz", "input_timeout": "s",
         "rotational_stiffness": "N·m/rad", "rest_radius": "m", "rest_window": "s", "velocity_window": "s"}
