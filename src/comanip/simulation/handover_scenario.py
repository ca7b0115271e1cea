"""Scenario ``handover`` (paper VI-B, docs/formulation.md §8): the robot leads, then hands the fine positioning to the person.

The robot plans a reach to the nominal goal with the Cartesian preset and holds the handle to it at
400 N/m (:func:`comanip.multicomponent.handover.plan_handover` gives the rest motion and the predicted
transition point: the distance T from the goal where a person would switch from the fast initial
sub-movement to the corrective one). When the release trigger fires (:mod:`comanip.simulation.handover_release`:
by default the handle itself comes within T of the goal; or, with ``release_trigger="estimate"``, within the
predicted T of the online estimate of the goal), the stiffness ramps to 0 (raised cosine) and the person, who
reaches for their own goal (the nominal one moved by the trial's task variation), finishes alone.

Per trial: when and where the switch happened against the prediction, the largest velocity change around
the switch, the final positioning error, the person's RMS force, and what released the robot (with the
estimate trigger: the estimate at the release, or the fallback at the plan's end). Over trials: the perpendicular position spread and the
velocity mean ± std against the distance to the goal, with the transition marked (paper Fig. 8).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from comanip.arguments import as_positive
from comanip.control.impedance import CartesianImpedanceController, RobotState
from comanip.estimation.streaming import online_settings
from comanip.multicomponent.perpendicular_dispersion import DispersionProfile, values_at_first_passage, perpendicular_dispersion_profile
from comanip.multicomponent.handover import DEFAULT_RAMP_TIME, HandoverSchedule, plan_handover, stiffness_profile
from comanip.multicomponent.transition_model import TransitionModel
from comanip.planning.plan import Plan
from comanip.progress import progress_bar
from comanip.simulation.rest_trajectory import RestTarget
from comanip.simulation.handover_release import (DEFAULT_SETTLE_FRACTION, EstimateRelease, GoalDistanceRelease,
                                                 check_release_trigger)
from comanip.simulation.measures import trial_measures
from comanip.simulation.policies.protocol import DEFAULT_UPDATE_INTERVAL
from comanip.simulation.person import solve_to_convergence
from comanip.simulation.scenario import ScenarioSettings, TrialRecord, run_trial
from comanip.simulation.setup import ScenarioSetup

#: Half-width (s) of the window over which a velocity change counts as one jump: v(t + 25 ms) - v(t - 25 ms).
RELEASE_ESTIMATOR = "correcting"
"""The description of the estimate trigger's estimator (:func:`comanip.estimation.streaming.online_settings.load`)."""
JUMP_HALF_WINDOW = 0.025
#: Points of the distance-to-goal grid of the scenario's profiles.
PROFILE_POINTS = 101


@dataclass(frozen=True)
class HandoverSettings(ScenarioSettings):
    """Inputs of the handover scenario (see :class:`ScenarioSettings` for the shared ones)."""

    ramp_time: float = DEFAULT_RAMP_TIME
    """Duration (s) of the stiffness ramp from 400 N/m to 0 (raised cosine)."""
    goal_variation: float = 0.0
    """Std (m) of the person's goal about the robot's, per horizontal axis and trial: task variation for the
    person's fine positioning to absorb. 0 (default): the person's own motor noise is the only variation,
    so the position spread shows where their reaches disperse (a variation of 1 cm outgrows it and moves
    the spread's peak onto the goal)."""
    release_trigger: str = "goal_distance"
    """What makes the robot let go (:mod:`comanip.simulation.handover_release`): "goal_distance" (default,
    the paper's: the handle within T of the goal the robot planned to, which it knows here) or "estimate"
    (the handle within T of the online goal estimate, once settled; the plan's end as a fallback)."""
    settle_fraction: float = DEFAULT_SETTLE_FRACTION
    """With the "estimate" trigger: the largest goal std an estimate may have to release, as a fraction of
    its predicted transition distance."""
    estimate_interval: float = DEFAULT_UPDATE_INTERVAL
    """With the "estimate" trigger: time between the observations fed to the estimator (s)."""

    def __post_init__(self):
        super().__post_init__()
        check_release_trigger(self.release_trigger)
        as_positive("settle_fraction", self.settle_fraction, "fraction of the transition distance")
        as_positive("estimate_interval", self.estimate_interval, "s")
        if not (isinstance(self.ramp_time, (int, float)) and np.isfinite(self.ramp_time) and self.ramp_time >= 0):
            raise ValueError(f"ramp_time must be a finite number ≥ 0 (s), got {self.ramp_time!r}")
        if not (isinstance(self.goal_variation, (int, float)) and np.isfinite(self.goal_variation) and self.goal_variation >= 0):
            raise ValueError(f"goal_variation must be a finite number ≥ 0 (m), got {self.goal_variation!r}")


class HandoverRobot:
    """Leads along the schedule's rest motion at 400 N/m; ramps to 0 once the release trigger fires
    (default: the handle within T of the schedule's goal)."""

    def __init__(self, controller: CartesianImpedanceController, schedule: HandoverSchedule, dt: float,
                 trigger: GoalDistanceRelease | EstimateRelease | None = None):
        self.controller, self.schedule, self.dt = controller, schedule, dt
        self.trigger = trigger or GoalDistanceRelease(schedule)
        self.switch_time: float | None = None
        self.switch_position: np.ndarray | None = None
        self.goal_estimate = self.trigger.goal_estimate
        self.controller.translational_stiffness = np.full(3, schedule.leading_stiffness)

    def command(self, t: float, state: RobotState, handle_force: np.ndarray) -> RestTarget:
        schedule = self.schedule
        if self.switch_time is None and self.trigger.due(t, state):
            self.switch_time, self.switch_position = t, state.position.copy()
        self.goal_estimate = self.trigger.goal_estimate     # the known goal, or the latest online estimate
        if self.switch_time is not None and t <= self.switch_time + schedule.ramp_time + self.dt:
            stiffness = float(stiffness_profile(t, self.switch_time, schedule.ramp_time, schedule.leading_stiffness))
            self.controller.translational_stiffness = np.full(3, stiffness)
        k = min(int(round((t - schedule.t[0]) / self.dt)), len(schedule.t) - 1)
        return RestTarget(schedule.rest_position[k], schedule.rest_velocity[k])


@dataclass
class HandoverTrial:
    """One handover trial: the record and its measures."""

    record: TrialRecord
    metrics: dict
    """Scalar measures (see :func:`handover_metrics`)."""


@dataclass
class HandoverRun:
    """All trials of one goal, the robot's plan and schedule, and the profiles over distance to the goal."""

    trials: list[HandoverTrial]
    plan: Plan
    """The robot's plan to the nominal goal."""
    schedule: HandoverSchedule
    """Its rest motion and the predicted transition."""
    dispersion: DispersionProfile
    """Perpendicular spread of the handle paths over progress toward the nominal goal."""
    speed_mean: np.ndarray
    """Handle speed at the first passage of each progress value (P,), m/s, mean over trials."""
    speed_std: np.ndarray
    """Its standard deviation over trials (P,), m/s."""

    @property
    def distance_to_goal(self) -> np.ndarray:
        """The profiles' grid as distance from the nominal goal along the start→goal line (P,), m."""
        return self.dispersion.distance_to_goal


def velocity_jump(record: TrialRecord, start: float, end: float) -> float:
    """Largest ||v(t + 25 ms) - v(t - 25 ms)|| (m/s) for t in [start, end] (s): how much the handle's velocity
    changes within 50 ms anywhere in the window."""
    dt = record.t[1] - record.t[0]
    half = int(round(JUMP_HALF_WINDOW / dt))
    k = np.flatnonzero((record.t >= start) & (record.t <= end))
    k = k[(k >= half) & (k < len(record.t) - half)]
    if len(k) == 0:
        return float("nan")
    return float(np.max(np.linalg.norm(record.velocity[k + half] - record.velocity[k - half], axis=1)))


def handover_metrics(record: TrialRecord, robot: HandoverRobot, width: float) -> dict:
    """Measures of one trial: switch time and distance against the prediction, the largest velocity change
    during the ramp (and, for comparison, over the same time just before it), the final error, the person's
    RMS interaction force (N, and its change from the holding force), and what released the robot: the
    trigger, the cause and, with the estimate trigger, the estimate at the release
    (:meth:`EstimateRelease.metrics`)."""
    schedule = robot.schedule
    switched = robot.switch_time is not None
    t_s = robot.switch_time if switched else float("nan")
    ramp_end = t_s + max(schedule.ramp_time, 2 * JUMP_HALF_WINDOW)
    final_error = float(np.linalg.norm(record.position[-1] - record.goal))
    forces = trial_measures(record, width, robot_axes=())
    return {
        "switched": switched,
        "switch_time_s": t_s,
        "predicted_switch_time_s": schedule.transition_time,
        "switch_delay_s": t_s - schedule.transition_time,
        "switch_distance_m": float(np.linalg.norm(robot.switch_position - schedule.goal)) if switched else float("nan"),
        "predicted_transition_distance_m": schedule.transition_distance,
        "velocity_jump_at_switch_m_per_s": velocity_jump(record, t_s, ramp_end) if switched else float("nan"),
        "velocity_change_before_switch_m_per_s":
            velocity_jump(record, 2 * t_s - ramp_end, t_s) if switched else float("nan"),
        "final_error_m": final_error,
        "within_width": final_error <= width,
        "person_goal_m": record.goal.tolist(),
        "rms_force_N": forces["rms_force_N"],
        "rms_force_change_N": forces["rms_force_change_N"],
        "replans": record.replans,
        "iteration_capped_replans": record.iteration_capped_replans,
    } | robot.trigger.metrics(record.goal)


class SpeedProfile(NamedTuple):
    """The hand's speed over trials at each progress value along the reach."""

    mean: np.ndarray
    """Mean speed (P,), m/s."""
    std: np.ndarray
    """Standard deviation over trials (P,), m/s."""


def speed_profile(paths: np.ndarray, speeds: np.ndarray, goal: np.ndarray, grid: np.ndarray) -> SpeedProfile:
    """Mean and std over trials (P,), m/s, of the speed (N, K) at the first passage of each progress value
    grid (P,), m, along the line from the common start paths[:, 0] (N, K, 3) to goal (3,)."""
    start = paths[0, 0]
    u = (goal - start) / np.linalg.norm(goal - start)
    along = (paths - start) @ u
    at_grid = np.stack([values_at_first_passage(a, v[:, None], grid)[:, 0] for a, v in zip(along, speeds)])
    return SpeedProfile(np.nanmean(at_grid, axis=0), np.nanstd(at_grid, axis=0, ddof=1))


def release_trigger(settings: HandoverSettings, setup: ScenarioSetup, start: np.ndarray, transition_model: TransitionModel,
                    schedule: HandoverSchedule, plan: Plan) -> GoalDistanceRelease | EstimateRelease:
    """One trial's release trigger as the settings ask. The estimate trigger's estimator (the ``correcting``
    description, :mod:`comanip.estimation.streaming.online_settings`: a person who corrects deviations from their
    plan) starts from the settled start [x; 0] (6,) with the robot's goal as its prior mean (weak default std),
    fed every ``estimate_interval`` by its loop; it falls back to releasing at the plan's end."""
    if settings.release_trigger == "goal_distance":
        return GoalDistanceRelease(schedule)
    described = online_settings.load(RELEASE_ESTIMATOR)
    described = described.replace(width=setup.width, loop=dataclasses.replace(described.loop, segmentation=None,
                                                                              rate=1.0 / settings.estimate_interval))
    loop = described.estimation_loop(start, prior_goal=schedule.goal, model=setup.model)
    loop.begin(0.0, start[:setup.model.n])                  # the trial's reach, from its start at t = 0
    return EstimateRelease(loop, transition_model, setup.width, settings.settle_fraction, fallback_time=float(plan.t[-1]))


def run_handover(settings: HandoverSettings, setup: ScenarioSetup | None = None, transition_model: TransitionModel | None = None,
                 progress: bool = True) -> HandoverRun:
    """Run the handover scenario's trials (one per seed), with a progress bar unless progress=False.

    transition_model: the model that predicts the transition distance (default: fitted on the shipped dataset).
    """
    setup = setup or ScenarioSetup(settings)
    transition_model = transition_model or TransitionModel()
    dt, duration = setup.world.timestep, setup.duration
    start = setup.settled_start(np.full(3, settings.robot_stiffness))
    goal, width = np.asarray(settings.goal), setup.width
    plan = solve_to_convergence(setup.planner, start.state, goal, width)
    schedule = plan_handover(plan, transition_model, settings.ramp_time, settings.robot_stiffness, rate=1.0 / dt)
    trials = []
    for k in progress_bar(f"handover to {np.round(goal, 2).tolist()}", settings.trials, "trial", progress, iterable=range(settings.trials)):
        variation = np.random.default_rng((settings.seed + k, 1)).standard_normal(2)   # apart from the motor noise
        person_goal = goal + np.r_[settings.goal_variation * variation, 0.0]
        person = setup.person(start, person_goal, settings.seed + k)
        robot = HandoverRobot(setup.world.controller, schedule, dt, release_trigger(settings, setup, start.state,
                                                                                   transition_model, schedule, plan))
        record = run_trial(setup.world, start, person, robot, duration)
        trials.append(HandoverTrial(record, handover_metrics(record, robot, width)))
    paths = np.stack([trial.record.position for trial in trials])
    speeds = np.stack([np.linalg.norm(trial.record.velocity, axis=1) for trial in trials])
    if len(trials) >= 2:
        dispersion = perpendicular_dispersion_profile(paths, goal, PROFILE_POINTS)
        speed_mean, speed_std = speed_profile(paths, speeds, goal, dispersion.progress)
    else:
        dispersion, speed_mean, speed_std = None, None, None
    return HandoverRun(trials, plan, schedule, dispersion, speed_mean, speed_std)
