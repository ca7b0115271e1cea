"""Scenario ``sync`` (paper VI-A, SPEC §8): the person leads x–y, the robot estimates the goal and leads z.

The robot starts with zero translational stiffness and the person starts their reach. At t_o = 0.2 s the
robot estimates the goal and the person's whole trajectory (:class:`comanip.estimation.GoalEstimator`,
Cartesian preset) from the start s_0 and the observed state s_o, sends the estimated trajectory's z as its
rest motion and sets the translational stiffness to [0, 0, 400] N/m. It never replans. As in the paper,
s_o is the handle's state at the model's step n_o = floor(t_o / h) (0.165 s), which the robot has recorded
on the way: handing the estimator the state at t_o itself, 35 ms later than the step it stands for, makes
the person look faster than they are, and the estimate overshoots the goal by tens of centimetres.

Per trial: the estimated goal, the error between the estimated trajectory and the handle over time
normalised by the movement time (paper Fig. 7, per axis), the time each axis reaches the goal, and the
velocity profiles of the person's intention and of the robot's end effector.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from comanip.analysis.speed_profile import speed_metrics
from comanip.arguments import as_positive, as_vector
from comanip.control.impedance import CartesianImpedanceController, RobotState
from comanip.estimation import GoalEstimator
from comanip.estimation.goal_prior import PAPER_PRIOR
from comanip.planning.plan import Plan
from comanip.simulation.rest_trajectory import RestTrajectory
from comanip.simulation.scenario import TABLE_CENTRE, ScenarioSettings, SettledStart, TrialRecord, check_workspace, reach_times, run_trial
from comanip.simulation.setup import ScenarioSetup

#: Points of the normalised-time grid on which tracking errors are reported.
NORMALISED_POINTS = 101


@dataclass(frozen=True)
class SyncSettings(ScenarioSettings):
    """Inputs of the synchronisation scenario (see :class:`ScenarioSettings` for the shared ones)."""

    observation_time: float = 0.2
    """t_o (s): when the robot observes the handle and estimates the goal (paper: 0.2 s)."""
    prior_goal: tuple = TABLE_CENTRE
    """The robot's prior goal g_bar (3,), m: where on the table things are usually placed."""
    known_height: bool = True
    """The placing height (the goal's z) is known, as in the paper: the estimated trajectory's z is moved,
    in proportion to its progress, to end there (:func:`end_at_height`). False: the estimate as it is."""

    def __post_init__(self):
        super().__post_init__()
        as_positive("observation_time", self.observation_time, "s")
        object.__setattr__(self, "prior_goal", tuple(check_workspace(
            as_vector("prior_goal", self.prior_goal, 3, "m, robot base frame"), "prior_goal").tolist()))


class SyncRobot:
    """Zero stiffness until t_o; then estimate once and lead z along the estimated trajectory."""

    def __init__(self, controller: CartesianImpedanceController, estimator: GoalEstimator, settings: SyncSettings,
                 start: SettledStart, prior_goal: np.ndarray, width: float, dt: float, duration: float,
                 warm_start: Plan | None = None):
        self.controller, self.estimator, self.settings = controller, estimator, settings
        self.start, self.prior_goal, self.width = start, prior_goal, width
        self.dt, self.duration = dt, duration
        h = estimator.model.h
        self.observation_step = int(np.floor(settings.observation_time / h + 1e-9))
        self.observation_time = self.observation_step * h
        """When s_o is taken (s): the model's step n_o."""
        self.observed: np.ndarray | None = None
        self.warm_start = warm_start
        """A previous trial's estimate to start the solver from (None: the estimator's own search)."""
        self.estimate: Plan | None = None
        self.rest: RestTrajectory | None = None
        self.controller.translational_stiffness = np.zeros(3)

    def command(self, t: float, state: RobotState) -> tuple[np.ndarray, np.ndarray]:
        position, velocity = state.position, state.velocity
        t_o = self.settings.observation_time
        if self.observed is None and t >= self.observation_time - 0.5 * self.dt:
            self.observed = np.r_[position, velocity]
        if self.rest is None:
            if t < t_o - 1e-9:
                return position, velocity            # no stiffness: the rest follows the handle
            # the paper's one-shot estimate, its prior weighted by W from the width (paper VI-A)
            self.estimate = self.estimator.estimate(self.start.state, self.observed, self.observation_time,
                                                    self.prior_goal, self.width, prior_std=PAPER_PRIOR,
                                                    warm_start=self.warm_start)
            self.rest = RestTrajectory(self.estimate, 0.0, self.dt, self.duration)
            if self.settings.known_height:
                end_at_height(self.rest, self.settings.goal[2])
            self.controller.translational_stiffness = [0.0, 0.0, self.settings.robot_stiffness]
        rest_position, rest_velocity = self.rest(t)
        # x and y are the person's: the rest follows the handle there, so only z is led
        position, velocity = position.copy(), velocity.copy()
        position[2], velocity[2] = rest_position[2], rest_velocity[2]
        return position, velocity


def end_at_height(rest: RestTrajectory, height: float) -> None:
    """Move the rest motion's z (in place) by (height - z_end) times its progress
    ||x(t) - x(0)|| / ||x_end - x(0)|| (clipped to [0, 1]): the estimated timing is kept, the end is the
    known height (m), and the start (the observed hand) is untouched."""
    position = rest.position
    progress = np.linalg.norm(position - position[0], axis=1) / max(np.linalg.norm(position[-1] - position[0]), 1e-9)
    progress = np.clip(progress, 0.0, 1.0)
    shift = height - position[-1, 2]
    position[:, 2] += shift * progress
    rest.velocity[:, 2] += shift * np.gradient(progress, rest.dt)


@dataclass
class SyncTrial:
    """One synchronisation trial: the record, the robot's estimate, and its measures."""

    record: TrialRecord
    estimate: Plan
    """The robot's estimated trajectory (``estimate.goal`` is g_hat); time axis of the plan."""
    estimated_position: np.ndarray
    """The estimated trajectory at the record's times (K, 3), m (with the known height, when used): the
    controller's rest before x–y are freed."""
    metrics: dict
    """Scalar measures (see :func:`sync_metrics`)."""
    normalised_time: np.ndarray
    """Grid (P,) from 0 to 1 over the movement time."""
    normalised_error: np.ndarray
    """Estimated trajectory minus handle position on that grid (P, 3), m."""


def sync_metrics(record: TrialRecord, estimate: Plan, estimated_position: np.ndarray, width: float,
                 observation_time: float) -> tuple[dict, np.ndarray, np.ndarray]:
    """Measures of one trial, and the tracking error on the normalised-time grid (P,), (P, 3).

    The movement time MT is SPEC §6's (first time after the peak speed below 5 % of it); errors are taken
    from t_o (when the estimate exists) to MT and reported on a grid of t / MT.
    """
    speed = np.linalg.norm(record.velocity, axis=1)
    timing = speed_metrics(record.t, speed)
    mt = timing.movement_time if timing.settled else record.t[-1]
    grid = np.linspace(0.0, 1.0, NORMALISED_POINTS)
    error = np.column_stack([np.interp(grid * mt, record.t, estimated_position[:, a] - record.position[:, a]) for a in range(3)])
    after = grid * mt >= observation_time
    goal_error = estimate.goal - record.goal
    axis_times = reach_times(record, width / 2)
    metrics = {
        "estimated_goal_m": estimate.goal.tolist(),
        "estimate_success": bool(estimate.success),
        "estimate_status": estimate.status,
        "estimate_time_s": float(estimate.solve_time),
        "goal_error_m": float(np.linalg.norm(goal_error)),
        "goal_error_xy_m": float(np.linalg.norm(goal_error[:2])),
        "goal_error_z_m": float(abs(goal_error[2])),
        "movement_time_s": float(mt),
        "peak_time_s": timing.t_peak,
        "asymmetry": timing.asymmetry,
        "rms_error_xy_m": float(np.sqrt(np.mean(np.sum(error[after, :2] ** 2, axis=1)))),
        "rms_error_z_m": float(np.sqrt(np.mean(error[after, 2] ** 2))),
        "max_error_z_m": float(np.max(np.abs(error[after, 2]))),
        "reach_time_x_s": float(axis_times[0]),
        "reach_time_y_s": float(axis_times[1]),
        "reach_time_z_s": float(axis_times[2]),
        "final_error_m": float(np.linalg.norm(record.position[-1] - record.goal)),
        "peak_speed_m_per_s": float(speed.max()),
        "replans": record.replans,
        "failed_replans": record.failed_replans,
    }
    return metrics, grid, error


def run_sync(settings: SyncSettings, setup: ScenarioSetup | None = None, progress: bool = True) -> list[SyncTrial]:
    """Run the synchronisation scenario's trials (one per seed), with a progress bar unless progress=False."""
    setup = setup or ScenarioSetup(settings)
    estimator = setup.estimator
    start = setup.settled_start(np.zeros(3))
    goal, width = np.asarray(settings.goal), setup.width
    prior = np.asarray(settings.prior_goal)
    first_plan = setup.person_first_plan(start, goal)
    trials = []
    for k in tqdm(range(settings.trials), desc=f"sync to {np.round(goal, 2).tolist()}", disable=not progress):
        person = setup.person(start, goal, settings.seed + k, first_plan)
        robot = SyncRobot(setup.world.controller, estimator, settings, start, prior, width, setup.world.timestep,
                          setup.duration, warm_start=_successful_estimate(trials))
        record = run_trial(setup.world, start, person, robot, setup.duration)
        estimated = np.array([robot.rest(t)[0] for t in record.t])
        metrics, grid, error = sync_metrics(record, robot.estimate, estimated, width, settings.observation_time)
        trials.append(SyncTrial(record, robot.estimate, estimated, metrics, grid, error))
    return trials


def _successful_estimate(trials: list[SyncTrial]) -> Plan | None:
    """The last trial's estimate if it converged (a good start for the next solve), else None."""
    return trials[-1].estimate if trials and trials[-1].estimate.success else None
