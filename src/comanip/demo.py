"""The main job on built-in defaults, in three steps (``comanip demo``):

1. **plan** a reach of the planar preset from rest at the origin to ``PLAN_GOAL`` (its mean hand path, the
   hand's uncertainty and its speed);
2. **predict a recorded person's goal online**: a recorded movement of the ``cursory`` data (a person's mouse
   reach, scaled to m), shifted to start at the origin, fed sample by sample as it happens (time since the
   onset s, position m, velocity m/s) to :class:`comanip.OnlineGoalEstimator` of the planar preset; each
   update's goal is compared with where the person was aiming (the recording's target);
3. **run the robot beside the same person** in the synchronisation scenario (:mod:`comanip.simulation.sync_scenario`):
   a simulated Panda and a person whose hand follows that recording, the robot leading the height along its
   online estimate of the person's goal (the ``continuous`` policy).

Needs the ``data`` extra (the recording) and, for step 3, the ``sim`` extra.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip import presets
from comanip.estimation import OnlineGoalEstimator
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
SYNC_POLICY = "continuous"
"""The sync robot's policy: the online goal estimate, updated as the hand moves."""


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
    estimator = OnlineGoalEstimator(model, np.zeros(2 * model.n))
    keep = np.flatnonzero((recording.t > recording.onset + 1e-9) & (recording.t <= recording.end_time + 1e-9))
    t, goals, stds, statuses = [], [], [], []
    for k in keep:
        estimate = estimator.update(recording.t[k] - recording.onset, recording.position[k] - origin, recording.velocity[k])
        t.append(recording.t[k] - recording.onset)
        goals.append(np.asarray(estimate.goal, dtype=float))
        stds.append(np.sqrt(np.clip(np.diag(np.asarray(estimate.goal_covariance, dtype=float)), 0.0, None)))
        statuses.append(str(estimate.status))
    return OnlinePrediction(recording, np.array(t), recording.position[keep] - origin, np.array(goals), np.array(stds),
                            statuses, np.asarray(recording.target, dtype=float) - origin)


def run_sync_beside(seed: int = 0):
    """Step 3: one sync trial (:data:`SYNC_GOAL`, :data:`SYNC_POLICY`) with the recorded person of ``seed``; the
    :class:`comanip.simulation.ScenarioResult` (its setup's ``recording(seed)`` is the movement played)."""
    from comanip.simulation import PersonParameters, SyncSettings, run_scenario

    settings = SyncSettings(goal=SYNC_GOAL, trials=1, seed=seed, policy=SYNC_POLICY,
                            person=PersonParameters(hand_path="recorded"))
    return run_scenario("sync", {SYNC_GOAL: settings}, None, progress=False)
