"""When the handover scenario's robot lets go: two release triggers behind one protocol.

- ``goal_distance`` (:class:`GoalDistanceRelease`): the handle is within the schedule's predicted transition
  distance T of the goal the robot planned to (the known goal).
- ``estimate`` (:class:`EstimateRelease`): the robot feeds the handle's position and velocity to an
  :class:`~comanip.estimation.EstimationLoop`, which updates its online estimator at the loop's rate (a person who
  corrects deviations, as the sync scenario's continuous policy assumes) and releases when the handle is within T_hat of the ESTIMATED
  goal g_hat, T_hat the transition model's distance for the estimated reach (|g_hat - x_0|, w). Only a
  settled estimate counts: a successful update whose goal covariance has its largest standard deviation at
  most ``settle_fraction`` · T_hat, so an early, wrong and uncertain estimate cannot release at once. If no
  settled estimate ever brings the handle within T_hat, the robot releases at ``fallback_time`` (the plan's
  end) and says so (cause ``fallback_plan_end``).

Positions m (robot base frame), velocities m/s, times s from the start of the reach.
"""

from __future__ import annotations

import warnings

import numpy as np

from comanip.control.impedance import RobotState
from comanip.estimation import EstimationLoop
from comanip.multicomponent.handover import HandoverSchedule
from comanip.multicomponent.transition_model import ExtrapolationWarning, TransitionModel

#: The release triggers by name.
RELEASE_TRIGGERS = ("goal_distance", "estimate")
#: Default largest goal std (as a fraction of T_hat) of an estimate that may release.
DEFAULT_SETTLE_FRACTION = 0.25


def check_release_trigger(name) -> str:
    """name if it is one of :data:`RELEASE_TRIGGERS`, else a ValueError that lists them."""
    if name not in RELEASE_TRIGGERS:
        raise ValueError(f"release_trigger must be one of {', '.join(RELEASE_TRIGGERS)}, got {name!r}")
    return name


class GoalDistanceRelease:
    """Release the first time the handle is within the schedule's T of the schedule's (known) goal."""

    name = "goal_distance"

    def __init__(self, schedule: HandoverSchedule):
        self.schedule = schedule
        self.cause: str | None = None

    @property
    def goal_estimate(self) -> np.ndarray:
        """Where the robot thinks the goal is (3,), m: the schedule's, which it knows."""
        return self.schedule.goal

    def due(self, t: float, state: RobotState) -> bool:
        if np.linalg.norm(state.position - self.schedule.goal) <= self.schedule.transition_distance:
            self.cause = self.name
            return True
        return False

    def metrics(self, person_goal: np.ndarray) -> dict:
        """The estimate measures of :meth:`EstimateRelease.metrics`, empty (NaN) here: no estimator runs."""
        nan = float("nan")
        return {"release_trigger": self.name, "release_cause": self.cause or "none", "release_fallback": False,
                "estimated_goal_m": None, "estimate_status": None, "estimate_goal_std_m": nan,
                "estimated_transition_distance_m": nan, "estimate_goal_error_m": nan, "estimate_updates": 0}


class EstimateRelease:
    """Release when the handle is within T_hat of a settled online goal estimate (module docstring).

    loop: a fresh :class:`~comanip.estimation.EstimationLoop` of this reach (one reach from the first sample, at the
    rate its estimator is updated); transition_model: gives T_hat; width: the goal width w (m) for it;
    settle_fraction: largest goal std allowed, as a fraction of T_hat; fallback_time: when to release anyway (s).
    """

    name = "estimate"

    def __init__(self, loop: EstimationLoop, transition_model: TransitionModel, width: float, settle_fraction: float,
                 fallback_time: float):
        self.loop, self.estimator = loop, loop.estimator
        self.transition_model, self.width = transition_model, width
        self.settle_fraction, self.fallback_time = settle_fraction, fallback_time
        self.transition_distance = float("nan")
        """T_hat (m) of the latest estimate."""
        self.goal_std = float("inf")
        """Largest std (m) of the latest estimate's goal covariance."""
        self.settled = False
        self.cause: str | None = None

    def _estimate(self, update) -> None:
        estimate = self.loop.estimate(update)
        covariance = np.asarray(estimate.goal_covariance)
        self.goal_std = float(np.sqrt(np.max(np.linalg.eigvalsh(covariance)))) if covariance.size else float("inf")
        distance = max(float(np.linalg.norm(estimate.goal - self.estimator.start_position)), 1e-6)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ExtrapolationWarning)     # an early estimate may lie off the data
            self.transition_distance = float(self.transition_model.predict(distance, self.width)[0])
        self.settled = bool(estimate.success and np.all(np.isfinite(estimate.goal)) and
                            self.goal_std <= self.settle_fraction * self.transition_distance)

    def due(self, t: float, state: RobotState) -> bool:
        self.loop.add_sample(t, state.position, state.velocity)
        update = self.loop.take_due()
        if update is not None:
            self._estimate(update)
            goal = self.estimator.latest.goal
            if self.settled and np.linalg.norm(state.position - goal) <= self.transition_distance:
                self.cause = self.name
                return True
        if t >= self.fallback_time - 1e-9:
            self.cause = "fallback_plan_end"
            return True
        return False

    @property
    def goal_estimate(self) -> np.ndarray:
        """The latest goal estimate (3,), m; the estimator's prior mean before the first update."""
        latest = self.estimator.latest
        return self.estimator.prior_mean if latest is None else np.asarray(latest.goal)

    def metrics(self, person_goal: np.ndarray) -> dict:
        """The estimate at the release (or at the end, if the robot never released): g_hat (m), its status,
        largest std (m), T_hat (m) and distance from the person's goal (m); the cause of the release."""
        latest = self.estimator.latest
        goal = None if latest is None else np.asarray(latest.goal)
        return {"release_trigger": self.name, "release_cause": self.cause or "none",
                "release_fallback": self.cause == "fallback_plan_end",
                "estimated_goal_m": None if goal is None else goal.tolist(),
                "estimate_status": None if latest is None else str(latest.status),
                "estimate_goal_std_m": self.goal_std, "estimated_transition_distance_m": self.transition_distance,
                "estimate_goal_error_m": float("nan") if goal is None else float(np.linalg.norm(goal - person_goal)),
                "estimate_updates": self.estimator.observation_count}
