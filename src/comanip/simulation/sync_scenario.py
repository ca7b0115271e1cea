"""Scenario ``sync`` (paper VI-A, docs/formulation.md §8): the person leads x–y, the robot predicts the goal and leads z.

The robot starts with zero translational stiffness and the person starts their reach. From t_o = 0.2 s on,
a robot policy (:mod:`comanip.simulation.policies`) predicts the goal and a rest motion; the robot sends that
motion's z as its rest and sets the translational stiffness to [0, 0, 400] N/m. The default policy,
``one-shot``, is the paper's: it estimates the goal and the person's whole trajectory once, at t_o
(:class:`comanip.estimation.GoalEstimator`, Cartesian preset), and never replans; the others are the
baselines (prior goal only, constant velocity, minimum-jerk fit, the height on a fixed minimum-jerk clock from the
onset), the passive robot, an admittance robot that follows the person's force, and comanip's online estimate,
leading along the model's reach to its goal (``continuous``) or along its forecast of the hand (``forecast``).

The task is the paper's: the person leads x–y and their arm follows the height the robot leads
(:mod:`comanip.simulation.following_arm`); with a robot that does not lead the height (passive, admittance), or in
the variant ``SyncSettings.person_leads_height``, the person intends the height too (:func:`person_axes`).

The person is the model's own by default; ``SyncSettings.person`` (:class:`comanip.simulation.person.PersonParameters`) makes them
move at another pace (``pace``) or along a recorded movement (``hand_path="recorded"``), so that a robot is not
rewarded only for assuming the person is the model.

Per trial: the goal estimate, the error between the predicted trajectory and the handle over time
normalised by the movement time (paper Fig. 7, per axis), the time each axis reaches the goal, the
velocity profiles of the person's intention and of the robot's end effector, and the co-manipulation
measures of :mod:`comanip.simulation.measures` (interaction force, work, synchronisation, arrival in step, goal error
over time).
"""

from __future__ import annotations

from typing import NamedTuple

from dataclasses import dataclass, replace

import numpy as np

from comanip import presets
from comanip.analysis.speed_profile import speed_metrics
from comanip.arguments import as_positive, as_vector
from comanip.control.impedance import CartesianImpedanceController, RobotState
from comanip.estimation import OnlineEstimate
from comanip.planning.plan import Plan
from comanip.progress import progress_bar
from comanip.simulation.rest_trajectory import RestTarget
from comanip.simulation.measures import trial_measures
from comanip.simulation.policies import POLICIES, ContinuousPolicy, PolicyContext, Prediction, RobotPolicy, check_policy
from comanip.simulation.policies.protocol import DEFAULT_UPDATE_INTERVAL
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
    """The placing height (the goal's z) is known, as in the paper: the predicted rest motion's z is moved,
    in proportion to its progress, to end there (:func:`end_at_height`). False: the prediction as it is.
    No policy uses the height to estimate the goal itself."""
    policy: str = "one-shot"
    """The robot policy, a name of :data:`comanip.simulation.policies.POLICIES` (default: the paper's)."""
    update_interval: float = DEFAULT_UPDATE_INTERVAL
    """Time between the predictions of the continuously updating policies (s)."""
    person_leads_height: bool = False
    """The variant of the task: True, the person intends the height too (their intention covers x, y and z, and a
    robot that leads the height leads it against or with them); False (the paper's task), the person leads x–y
    only and their arm follows the height the robot leads (:mod:`comanip.simulation.following_arm`). With a robot
    that does not lead the height (:attr:`RobotPolicy.leads_height` false: passive, admittance) the person intends
    it either way: someone must move it. The scenario sets the person's ``led_axes`` accordingly."""
    online_preset: str | None = None
    """The reaching model of the continuous policy's online goal estimator, a preset name of
    :mod:`comanip.presets` (e.g. ``"arm"``, a person's arm in 3-D); None: the scenario's model (the Cartesian
    preset)."""
    carry_calibration: bool = False
    """True: the estimating robots (``continuous``, ``forecast``) keep what they learned of the person from trial to
    trial of a run (:mod:`comanip.estimation.calibration.person_calibration`: amplitude, pace and spread), so trial k
    (seed + k) starts with the calibration learned from trials 0..k-1, in seed order; each run (one person, goal and
    policy) starts with a person not seen yet. False: every trial's robot meets a person not seen yet."""

    def __post_init__(self):
        super().__post_init__()
        as_positive("observation_time", self.observation_time, "s")
        check_policy(self.policy)
        if self.online_preset is not None and self.online_preset not in presets.names():
            raise ValueError(f"online_preset must be one of {presets.names()} or None, got {self.online_preset!r}")
        as_positive("update_interval", self.update_interval, "s")
        if not isinstance(self.carry_calibration, bool):
            raise ValueError(f"carry_calibration must be True or False, got {self.carry_calibration!r}")
        object.__setattr__(self, "prior_goal", tuple(check_workspace(
            as_vector("prior_goal", self.prior_goal, 3, "m, robot base frame"), "prior_goal").tolist()))


class PolicyRobot:
    """Zero stiffness until t_o; then leads z along the rest motion of the policy's latest prediction, its
    ``lead_share`` of the way from the handle (x and y stay free: the rest follows the handle there), asking the
    policy again every update_interval."""

    def __init__(self, controller: CartesianImpedanceController, policy: RobotPolicy, settings: SyncSettings):
        self.controller, self.policy, self.settings = controller, policy, settings
        self.prediction: Prediction | None = None
        self.predictions = 0
        """Predictions made so far."""
        self.goal_estimate: np.ndarray | None = None
        self.history: list[tuple[float, RestTrajectory]] = []
        """(time s, rest motion) of every prediction made: the robot's forecasts of the handle."""
        self._next_update = settings.observation_time
        self.controller.translational_stiffness = np.zeros(3)

    def command(self, t: float, state: RobotState, handle_force: np.ndarray) -> RestTarget:
        position, velocity = state.position, state.velocity
        self.policy.observe(t, position, velocity, handle_force)
        if t >= self._next_update - 1e-9:
            interval = self.policy.update_interval
            self._next_update = np.inf if interval is None else self._next_update + interval
            prediction = self.policy.predict(t)
            if prediction is not None:
                if self.settings.known_height and self.policy.leads_height:
                    end_at_height(prediction.rest, self.settings.goal[2])
                self.prediction, self.goal_estimate = prediction, prediction.goal
                self.predictions += 1
                self.history.append((t, prediction.rest))
                self.controller.translational_stiffness = [0.0, 0.0, self.settings.robot_stiffness]
        if self.prediction is None:
            return RestTarget(position, velocity)            # no stiffness: the rest follows the handle
        rest_position, rest_velocity = self.prediction.rest(t)
        share = self.prediction.lead_share
        position, velocity = position.copy(), velocity.copy()
        position[2] += share * (rest_position[2] - position[2])
        velocity[2] += share * (rest_velocity[2] - velocity[2])
        return RestTarget(position, velocity)


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
    """One synchronisation trial: the record, the robot's last prediction, and its measures."""

    record: TrialRecord
    policy: str
    """The robot policy's name."""
    estimate: Plan | OnlineEstimate | None
    """The model's estimate behind the last prediction (``estimate.goal`` is g_hat), for the model-based
    policies; None for the others."""
    estimated_position: np.ndarray
    """The last prediction's rest motion at the record's times (K, 3), m (with the known height, when
    used); NaN for a policy that never predicts."""
    metrics: dict
    """Scalar measures (see :func:`sync_metrics`)."""
    normalised_time: np.ndarray
    """Grid (P,) from 0 to 1 over the movement time."""
    normalised_error: np.ndarray
    """Predicted trajectory minus handle position on that grid (P, 3), m."""


class SyncMetrics(NamedTuple):
    """The measures of one sync trial and its tracking error over normalised time."""

    metrics: dict
    """Scalar measures by name (:func:`comanip.simulation.measures.trial_measures` and the paper's Fig. 7 errors)."""
    grid: np.ndarray
    """Normalised time t / MT (P,)."""
    error: np.ndarray
    """Tracking error on the grid (P, 3), m."""


def forecast_error(record: TrialRecord, history, until: float) -> float:
    """The robot's forecast error (m): for every prediction made at a time t_i before ``until`` (s; the movement
    time), the RMS distance between its rest motion and the handle over [t_i, until], averaged over the
    predictions; NaN when there is none. history: (t_i s, :class:`RestTrajectory`) pairs, as
    :attr:`PolicyRobot.history` records them."""
    errors = []
    for made_at, rest in history:
        keep = (record.t >= made_at - 1e-9) & (record.t <= until + 1e-9)
        if made_at < until and keep.any():
            distance = np.linalg.norm(rest.positions(record.t[keep]) - record.position[keep], axis=1)
            errors.append(np.sqrt(np.mean(distance**2)))
    return float(np.mean(errors)) if errors else float("nan")


def sync_metrics(record: TrialRecord, goal_estimate: np.ndarray | None, estimated_position: np.ndarray, width: float,
                 observation_time: float, history=()) -> SyncMetrics:
    """Measures of one trial (:func:`comanip.simulation.measures.trial_measures` and the paper's Fig. 7
    errors, and the forecast error of :func:`forecast_error` over the robot's ``history`` of predictions), and
    the tracking error on the normalised-time grid (P,), (P, 3).

    goal_estimate: the robot's last goal estimate (3,), m, or None. The tracking errors are taken from t_o
    (when the first estimate exists) to MT and reported on a grid of t / MT (NaN when MT < t_o); force and
    work from t_o on.
    """
    measures = trial_measures(record, width, from_time=observation_time)
    speed = np.linalg.norm(record.velocity, axis=1)
    timing = speed_metrics(record.t, speed)
    mt = measures["movement_time_s"]
    grid = np.linspace(0.0, 1.0, NORMALISED_POINTS)
    error = np.column_stack([np.interp(grid * mt, record.t, estimated_position[:, a] - record.position[:, a]) for a in range(3)])
    after = grid * mt >= observation_time
    goal_error = (np.full(3, np.nan) if goal_estimate is None else goal_estimate) - record.goal
    axis_times = reach_times(record, width / 2)
    metrics = {
        "estimated_goal_m": None if goal_estimate is None else np.asarray(goal_estimate).tolist(),
        "goal_error_m": float(np.linalg.norm(goal_error)),
        "goal_error_xy_m": float(np.linalg.norm(goal_error[:2])),
        "goal_error_z_m": float(abs(goal_error[2])),
        "peak_time_s": timing.t_peak,
        "asymmetry": timing.asymmetry,
        # NaN when the movement ended before t_o (nothing was predicted during it)
        "rms_error_xy_m": float(np.sqrt(np.mean(np.sum(error[after, :2] ** 2, axis=1)))) if after.any() else float("nan"),
        "rms_error_z_m": float(np.sqrt(np.mean(error[after, 2] ** 2))) if after.any() else float("nan"),
        "max_error_z_m": float(np.max(np.abs(error[after, 2]))) if after.any() else float("nan"),
        "reach_time_x_s": float(axis_times[0]),
        "reach_time_y_s": float(axis_times[1]),
        "reach_time_z_s": float(axis_times[2]),
        "peak_speed_m_per_s": float(speed.max()),
        "forecast_error_mean_m": forecast_error(record, history, mt),
        "replans": record.replans,
        "iteration_capped_replans": record.iteration_capped_replans,
        **measures,
    }
    return SyncMetrics(metrics, grid, error)


def person_axes(settings: SyncSettings) -> tuple:
    """The axes the settings' person leads (indices): x–y in the paper's task, when the robot leads the height; x, y
    and z when they intend the height too (``person_leads_height``) or the robot does not lead it."""
    if settings.person_leads_height or not POLICIES[settings.policy].leads_height:
        return (0, 1, 2)
    return (0, 1)


def policy_context(settings: SyncSettings, setup: ScenarioSetup, start: SettledStart) -> PolicyContext:
    """What every policy knows before the reach, for the settings' prior goal (the prior plan is solved here)."""
    prior = np.asarray(settings.prior_goal)
    online_model = setup.online_model(settings.online_preset)
    return PolicyContext(start=start.state, prior_goal=prior, width=setup.width, observation_time=settings.observation_time,
                         dt=setup.world.timestep, duration=setup.trial_duration(settings.person), model=setup.model,
                         online_model=online_model, online_width=setup.width if settings.online_preset is None else online_model.width,
                         estimator=setup.estimator,
                         prior_plan=setup.person_first_plan(start, prior), update_interval=settings.update_interval,
                         goal_height=float(settings.goal[2]) if settings.known_height else None)


def run_sync(settings: SyncSettings, setup: ScenarioSetup | None = None, progress: bool = True) -> list[SyncTrial]:
    """Run the synchronisation scenario's trials (one per seed) with the settings' policy, with a progress bar
    unless progress=False. Trial k's person (seed + k) is the same whatever the policy; with
    ``settings.carry_calibration`` an estimating robot starts trial k knowing what it learned of them in trials
    0..k-1 (each trial's metrics say what: :func:`calibration_metrics`)."""
    setup = setup or ScenarioSetup(settings)
    start = setup.settled_start(np.zeros(3))
    goal, width = np.asarray(settings.goal), setup.width
    first_plan = setup.person_first_plan(start, goal)
    context = policy_context(settings, setup, start)
    trials = []
    person_parameters = replace(settings.person, led_axes=person_axes(settings))
    calibration = None
    for k in progress_bar(f"sync {settings.policy} to {np.round(goal, 2).tolist()}", settings.trials, "trial", progress,
                           iterable=range(settings.trials)):
        person = setup.person(start, goal, settings.seed + k, first_plan, person_parameters)
        policy = POLICIES[settings.policy](replace(context, warm_start=_successful_estimate(trials), person=calibration))
        known = calibration_metrics(policy)
        robot = PolicyRobot(setup.world.controller, policy, settings)
        record = run_trial(setup.world, start, person, robot, context.duration)
        if settings.carry_calibration and isinstance(policy, ContinuousPolicy):
            calibration = policy.finish_trial()
        prediction = robot.prediction
        estimated = np.full((len(record.t), 3), np.nan) if prediction is None else np.array([prediction.rest(t)[0] for t in record.t])
        metrics, grid, error = sync_metrics(record, robot.goal_estimate, estimated, width, settings.observation_time,
                                            robot.history)
        metrics.update(predictions=robot.predictions, **known)
        if prediction is not None and prediction.estimate is not None and prediction.estimate is not context.prior_plan:
            estimate = prediction.estimate
            metrics.update(estimate_success=bool(estimate.success), estimate_status=str(estimate.status),
                           estimate_time_s=float(estimate.solve_time))
        trials.append(SyncTrial(record, settings.policy, None if prediction is None else prediction.estimate, estimated,
                                metrics, grid, error))
    return trials


def calibration_metrics(policy: RobotPolicy) -> dict:
    """What an estimating robot (continuous, forecast) knows of the person as its trial starts: the reaches it has
    learned from (``calibration_reaches``) and its amplitude, pace and spread factors (1 for a person not seen
    yet); {} for the other policies."""
    if not isinstance(policy, ContinuousPolicy):
        return {}
    person = policy.estimator.person
    return {"calibration_reaches": person.reaches, "calibration_amplitude": person.amplitude,
            "calibration_pace": person.pace, "calibration_spread": person.spread}


def _successful_estimate(trials: list[SyncTrial]) -> Plan | None:
    """The last trial's one-shot estimate if it converged (a good start for the next solve), else None."""
    estimate = trials[-1].estimate if trials else None
    return estimate if isinstance(estimate, Plan) and estimate.success else None
