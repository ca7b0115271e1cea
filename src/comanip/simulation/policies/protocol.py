"""What every robot policy of the synchronisation scenario shares: its inputs, its prediction, its protocol.

A policy watches the handle (position m, velocity m/s, the person's force on it N, robot base frame, time s from
the start of the person's reach) at every control step, and from t_o on predicts the person's goal and a rest motion for
the axes the robot leads. The scenario's robot (:class:`comanip.simulation.sync_scenario.PolicyRobot`)
asks for a prediction at t_o and then every ``update_interval`` seconds, and drives the controller.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Protocol

import numpy as np

from comanip.analysis.speed_profile import speed_metrics
from comanip.estimation import GoalEstimator, OnlineEstimate, PersonCalibration
from comanip.model import ReachingModel
from comanip.planning.plan import Plan
from comanip.simulation.rest_trajectory import RestTrajectory

#: Time between a continuously updating policy's predictions (s): 20 ms, 50 Hz.
DEFAULT_UPDATE_INTERVAL = 0.02


@dataclass(frozen=True)
class PolicyContext:
    """What a policy knows before the reach: the same for every policy and trial of one goal."""

    start: np.ndarray
    """The handle's state at the start of the reach, [x; v] (6,), m and m/s (at rest: v = 0)."""
    prior_goal: np.ndarray
    """The robot's prior goal g_bar (3,), m."""
    width: float
    """The goal width w (m) the robot assumes."""
    observation_time: float
    """t_o (s): when the robot first predicts and starts leading."""
    dt: float
    """Control period (s)."""
    duration: float
    """Simulated time of a trial from the start (s): how far rest motions must reach."""
    model: ReachingModel
    """The reaching model the model-based policies use (the Cartesian preset)."""
    online_model: ReachingModel
    """The reaching model of the continuous policy's online goal estimator (``SyncSettings.online_preset``)."""
    online_width: float
    """The goal width (m) that estimator assumes: ``width`` with the scenario's model, else the online model's own."""
    estimator: GoalEstimator
    """The one-shot goal estimator (built once per scenario)."""
    prior_plan: Plan
    """The model's converged reach from the start to the prior goal."""
    update_interval: float = DEFAULT_UPDATE_INTERVAL
    """Time between predictions of the continuously updating policies (s)."""
    warm_start: Plan | None = None
    """A previous trial's one-shot estimate to start that solver from (None: the estimator's own search)."""
    goal_height: float | None = None
    """The placing height (m) when the scenario knows it (``SyncSettings.known_height``), else None. The robot
    applies it to every prediction (:func:`comanip.simulation.sync_scenario.end_at_height`); a policy may lead to
    it itself."""
    person: PersonCalibration | None = None
    """What the robot knows of the person when the trial starts: the calibration the estimating policies
    (continuous, forecast) apply to their online estimates and learn into from the trial's reach, in place
    (``finish_trial()``); None: a person not seen yet (:attr:`comanip.simulation.sync_scenario.SyncSettings.carry_calibration`)."""

    @cached_property
    def expected_movement_time(self) -> float:
        """The movement time (docs/formulation.md §6) of the model's reach to the prior goal (s): how long the robot
        expects a reach to take before it has seen one."""
        timing = speed_metrics(self.prior_plan.t, self.prior_plan.ee_speed)
        return float(timing.movement_time if timing.settled else self.prior_plan.t[-1])

    def rest_from(self, t: float, position: np.ndarray, velocity: np.ndarray) -> RestTrajectory:
        """A rest motion sampled from real time t (s) to the trial's end: position (N, 3) m, velocity
        (N, 3) m/s at t + k·dt; shorter arrays are held at their last sample."""
        steps = int(np.ceil(max(self.duration - t, 0.0) / self.dt)) + 2
        position, velocity = np.asarray(position, dtype=float), np.asarray(velocity, dtype=float)
        if len(position) < steps:
            extra = steps - len(position)
            position = np.vstack([position, np.repeat(position[-1:], extra, axis=0)])
            velocity = np.vstack([velocity, np.zeros((extra, velocity.shape[1]))])
        return RestTrajectory(position[:steps], velocity[:steps], t, self.dt)

    def rest_times(self, t: float) -> np.ndarray:
        """The times (N,), s, from t to the trial's end every dt, on which :meth:`rest_from` samples."""
        return t + self.dt * np.arange(int(np.ceil(max(self.duration - t, 0.0) / self.dt)) + 2)


@dataclass
class Prediction:
    """A policy's answer at one update."""

    goal: np.ndarray
    """The predicted goal g_hat (3,), m."""
    rest: RestTrajectory
    """The rest motion the robot leads along (its z is used in the sync scenario), real time."""
    estimate: Plan | OnlineEstimate | None = None
    """The model's estimate behind the prediction, for the model-based policies: the one-shot estimate (a
    :class:`~comanip.estimation.GoalEstimate`, a plan), the online one or the prior's plan."""
    lead_share: float = 1.0
    """How far the robot's rest goes from the handle towards the rest motion on the axes it leads, in [0, 1]:
    rest = x + s (rest motion - x), and likewise its velocity, x the handle. 1: the rest motion itself; below 1
    the robot gives way, its spring and damper pulling the handle towards the motion with s times their force."""

    def __post_init__(self):
        if not (isinstance(self.lead_share, (int, float)) and 0.0 <= self.lead_share <= 1.0):
            raise ValueError(f"lead_share must be a number in [0, 1], got {self.lead_share!r}")


class RobotPolicy(Protocol):
    """A robot policy: sees the handle every step, predicts at t_o and then every update_interval."""

    name: str
    """The policy's name in :data:`comanip.simulation.policies.POLICIES`."""
    update_interval: float | None
    """Time between predictions after t_o (s); None: one prediction, at t_o."""
    leads_height: bool
    """Whether the robot leads the height (the axes the scenario gives it) toward a predicted motion. False (the
    passive and admittance robots): the person must move the height themselves, and the scenario's person intends
    it (:attr:`comanip.simulation.sync_scenario.SyncSettings.person_leads_height`)."""

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        """The handle at time t (s): position (3,) m, velocity (3,) m/s, and the person's force on it (3,) N as a
        wrist force sensor reads it; called at every control step."""

    def predict(self, t: float) -> Prediction | None:
        """The goal and rest motion from what was observed up to time t (s); None: do not lead."""
