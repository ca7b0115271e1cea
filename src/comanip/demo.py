"""The main job on built-in defaults, in three steps (``comanip demo``):

1. **plan** a reach of the planar preset from rest at the origin to ``PLAN_GOAL`` (its mean hand path, the
   hand's uncertainty and its speed);
2. **predict a recorded person's goal online**: a recorded movement of the ``cursory`` data (a person's mouse
   reach, scaled to m), shifted to start at the origin, fed sample by sample as it happens (time since the
   onset s, position m, velocity m/s) through the loop of an online estimator of the planar preset (the
   ``recorded`` description, :mod:`comanip.estimation.streaming.online_settings`); each
   update's goal is compared with where the person was aiming (the recording's target, which these recordings
   hold and the arm recordings of step 3 do not);
3. **run the robot beside a person guiding the handle** in the synchronisation scenario
   (:mod:`comanip.simulation.sync_scenario`): a simulated Panda and a person whose hand follows a recorded arm
   reach (:data:`SYNC_PERSON`), the robot leading the height along its online estimate's forecast of the person's
   hand (the ``forecast`` policy). What the robot believed along the way is read back by :func:`robot_forecasts`: the
   goal estimate over time and, at :data:`FORECAST_FRACTIONS` of the movement, its forecast of the hand's path.

Needs the ``data`` extra (step 2's recording), the ``sim`` extra (step 3) and the arm reaches of
``examples/data/arm_reaches`` (a clone of the source: :data:`comanip.simulation.people.SHIPPED_ARM_REACHES`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip import presets
from comanip.estimation.streaming import online_settings
from comanip.estimation.streaming.estimation_loop import LoopSettings
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner
from comanip.recordings.recording import Recording

PLAN_GOAL = (0.3, 0.1)
"""Goal of the planned reach (m), planar preset."""
PLAN_WIDTH = 0.02
"""Width of the planned reach's goal (m)."""
FRACTIONS = (0.2, 0.4, 0.6, 0.8, 1.0)
"""Fractions of the recorded movement time at which the online estimate's error is reported."""
SYNC_GOAL = "near"
"""The sync scenario's goal (a name of :data:`comanip.simulation.NAMED_GOALS`)."""
SYNC_POLICY = "forecast"
"""The sync robot's policy: the online goal estimate's forecast of the hand, updated as the hand moves."""
SYNC_PERSON = "arm-x2.5"
"""The sync scenario's person (:func:`comanip.simulation.people.choose_person`): a recorded arm reach played 2.5
times slower. A fingertip pointing 0.22 m takes 0.42 s (the median of the recorded arm reaches); a person moving
a handle whose apparent mass is 7–16 kg moves it more slowly, and 2.5 is the slow-down that gives the median
recorded mouse movement the model's person's time with this handle (one rule for every recorded person, chosen
before these reaches were played)."""
GUIDING_FORCE_N = (10.0, 30.0)
"""The force people exchange when one guides the other through a held contact (N): 10–30 N between partners in a
partnered stepping task (Sawers et al. 2017, J. NeuroEng. Rehabil. 14:8). The report puts the person's force
against it."""
FORECAST_FRACTIONS = (0.25, 0.5, 0.75)
"""Fractions of the movement time at which the report and the figure show the robot's forecast of the hand."""
QUANTITIES = {"goal": "the goal estimate over time", "path": "the predicted path of the hand against the hand",
              "force": "the force between the person and the handle"}
"""The names the report and the figure of step 3 give what they show."""


def against_range(value: float, bounds: tuple[float, float]) -> str:
    """Where value lies against bounds (low, high): "below", "within" or "above"."""
    low, high = bounds
    return "below" if value < low else "above" if value > high else "within"


@dataclass
class OnlinePrediction:
    """The online estimates along one recorded movement, shifted to start at the origin."""

    recording: Recording
    """The recorded movement (positions as recorded, m)."""
    t: np.ndarray
    """Update times (U,), s since the movement's onset."""
    position: np.ndarray
    """The hand at each update (U, 2), m, from the start."""
    goal: np.ndarray
    """Each update's estimated goal (U, 2), m, from the start."""
    goal_std: np.ndarray
    """Each update's goal standard deviations (U, 2), m."""
    status: list[str]
    """Each update's status."""
    target: np.ndarray
    """Where the person aimed (2,), m, from the start."""

    @property
    def error(self) -> np.ndarray:
        """Distance of each update's goal from the target (U,), m."""
        return np.linalg.norm(self.goal - self.target, axis=1)

    def error_at(self, fraction: float) -> float:
        """The error (m) of the last update at or before ``fraction`` of the movement time."""
        k = np.searchsorted(self.t, fraction * self.recording.movement_time + 1e-9, side="right") - 1
        return float(self.error[max(k, 0)])


def plan_reach(model=None) -> Plan:
    """Step 1: the planar preset's reach from rest at the origin to :data:`PLAN_GOAL`."""
    model = model or presets.planar()
    return Planner(model).solve(np.zeros(2 * model.n), PLAN_GOAL, PLAN_WIDTH)


def predict_online(recording: Recording, model=None) -> OnlinePrediction:
    """Step 2: feed the recording's samples from its onset to its end, one update each, to an online estimator
    of the planar preset started at rest at the movement's start."""
    model = model or presets.planar()
    if recording.target is None or recording.position.shape[1] != model.d:
        raise ValueError(f"the recording must be {model.d}-D with a known target, got {recording.position.shape[1]}-D "
                         f"and target {recording.target}")
    origin = recording.start
    settings = online_settings.load("recorded").replace(model="planar", loop=LoopSettings(segmentation=None))   # one reach
    loop = settings.estimation_loop(model=model)
    loop.begin(0.0, np.zeros(model.d))                   # the reach, at rest at the origin at its onset
    keep = np.flatnonzero((recording.t > recording.onset + 1e-9) & (recording.t <= recording.end_time + 1e-9))
    t, goals, stds, statuses = [], [], [], []
    for k in keep:
        loop.add_sample(recording.t[k] - recording.onset, recording.position[k] - origin, recording.velocity[k])
        estimate = loop.estimate(loop.take_due())
        t.append(recording.t[k] - recording.onset)
        goals.append(np.asarray(estimate.goal, dtype=float))
        stds.append(np.sqrt(np.clip(np.diag(np.asarray(estimate.goal_covariance, dtype=float)), 0.0, None)))
        statuses.append(str(estimate.status))
    return OnlinePrediction(recording, np.array(t), recording.position[keep] - origin, np.array(goals), np.array(stds),
                            statuses, np.asarray(recording.target, dtype=float) - origin)


@dataclass
class Forecast:
    """The robot's forecast of the hand made at one update, on the trial's samples from then to the movement's end."""

    made_at: float
    """Time of the update (s from the start of the reach)."""
    goal: np.ndarray
    """The goal estimate of that update (3,), m."""
    t: np.ndarray
    """Times (F,), s, from ``made_at`` to the movement time MT."""
    position: np.ndarray
    """The forecast hand (F, 3), m: the estimate's predicted path of the hand (``ee_mean``), held at its last point
    after the estimate's horizon."""
    hand: np.ndarray
    """The handle at those times (F, 3), m."""

    @property
    def error(self) -> np.ndarray:
        """Distance of the forecast from the hand (F,), m."""
        return np.linalg.norm(self.position - self.hand, axis=1)

    @property
    def rms_error(self) -> float:
        """RMS of :attr:`error` (m): how far the forecast was from where the hand went."""
        return float(np.sqrt(np.mean(self.error**2)))


def run_sync_beside(seed: int = 0):
    """Step 3: one sync trial (:data:`SYNC_GOAL`, :data:`SYNC_POLICY`, :data:`SYNC_PERSON`) whose person plays
    recording ``seed`` (:meth:`comanip.simulation.ScenarioSetup.recording`); the
    :class:`comanip.simulation.ScenarioResult`."""
    from comanip.simulation import SyncSettings, choose_person, run_scenario

    person = choose_person(SYNC_PERSON)
    settings = SyncSettings(goal=SYNC_GOAL, trials=1, seed=seed, policy=SYNC_POLICY, person=person.parameters)
    return run_scenario("sync", {SYNC_GOAL: settings}, None, progress=False, arm_reaches=person.arm_reaches)


def robot_forecasts(result) -> list[Forecast]:
    """The robot's forecasts of the hand in the sync trial of ``result`` (:func:`run_sync_beside`) at
    :data:`FORECAST_FRACTIONS` of its movement time: the robot's estimator fed again the handle states the robot
    saw (the same samples at the same times give the same estimates), read at the last update at or before each
    fraction."""
    from comanip.simulation.policies import POLICIES
    from comanip.simulation.sync_scenario import policy_context

    settings, setup = result.settings, result.setup
    trial = result.goals[SYNC_GOAL].trials[0]
    record, movement_time = trial.record, trial.metrics["movement_time_s"]
    policy = POLICIES[settings.policy](policy_context(settings, setup, setup.settled_start(np.zeros(3))))
    wanted = [f * movement_time for f in FORECAST_FRACTIONS]
    forecasts = []
    for k, t in enumerate(record.t):
        if t > wanted[len(forecasts)] + 1e-9:
            forecasts.append(_forecast(policy.estimator.latest, record, movement_time))
            if len(forecasts) == len(wanted):
                break
        policy.observe(t, record.position[k], record.velocity[k], record.person_force[k])
    return forecasts


def _forecast(estimate, record, movement_time: float) -> Forecast:
    """The estimate's predicted path of the hand against the record's handle from the estimate's last observation
    (its ``t_obs``, s) to the movement time (s)."""
    made_at = float(estimate.t_obs)
    keep = (record.t >= made_at - 1e-9) & (record.t <= movement_time + 1e-9)
    t = record.t[keep]
    path = np.column_stack([np.interp(t, estimate.path.t, estimate.path.position[:, a]) for a in range(3)])
    return Forecast(made_at, np.array(estimate.goal, dtype=float), t, path, record.position[keep])
