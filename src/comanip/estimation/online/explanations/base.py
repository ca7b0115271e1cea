"""What an explanation of a reach in progress sees and gives.

An explanation is one account of the hand's movement so far, e.g. the reaching model at its own pace. Given
the observations of the reach (:class:`HandTrace`) and the estimator's latest estimate, it gives a goal, its
covariance and its :class:`Verdict` on the hand (:class:`Explained`). The online estimator asks its explanations in
order and takes the first whose verdict is :attr:`Verdict.EXPLAINS` (:mod:`comanip.estimation.online.online_estimator`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import Enum
from typing import NamedTuple, Protocol

import numpy as np

from comanip.estimation.people.endpoint_baselines import MOVING_SPEED
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.hand_rest import has_left
from comanip.estimation.model_reaches.profile_fit import detected_onset
from comanip.estimation.model_reaches.reach_family import ReachFamily, ReachPrediction
from comanip.estimation.model_reaches.reach_timing import ReachTiming
from comanip.estimation.estimate_status import EstimateStatus
from comanip.optim import Status


class HandTrace:
    """The observations of one reach: times (K,) s, positions (K, d) m and velocities (K, d) m/s, in order."""

    def __init__(self, d: int):
        self._rows = np.zeros((64, 1 + 2 * d))
        self.count = 0
        """Observations so far."""
        self.d = d
        self._onset: tuple[int, float | None] = (0, None)    # (count, onset) of the last onset found
        self._left: tuple[bytes, int, bool] = (b"", 0, False)  # (start, count checked, whether it left) of has_left

    def append(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> None:
        if self.count == len(self._rows):
            self._rows = np.concatenate([self._rows, np.zeros_like(self._rows)])
        row = self._rows[self.count]
        row[0], row[1:1 + self.d], row[1 + self.d:] = time_s, position, velocity
        self.count += 1

    def extend(self, times_s: np.ndarray, positions: np.ndarray, velocities: np.ndarray) -> None:
        """Observations (K,) s, (K, d) m, (K, d) m/s appended in order."""
        count = len(times_s)
        while self.count + count > len(self._rows):
            self._rows = np.concatenate([self._rows, np.zeros_like(self._rows)])
        rows = self._rows[self.count:self.count + count]
        rows[:, 0], rows[:, 1:1 + self.d], rows[:, 1 + self.d:] = times_s, positions, velocities
        self.count += count

    @property
    def t(self) -> np.ndarray:
        return self._rows[:self.count, 0]

    @property
    def position(self) -> np.ndarray:
        return self._rows[:self.count, 1:1 + self.d]

    @property
    def velocity(self) -> np.ndarray:
        return self._rows[:self.count, 1 + self.d:]

    @property
    def last_time(self) -> float:
        """Time of the newest observation (s); -inf before the first."""
        return float(self._rows[self.count - 1, 0]) if self.count else -math.inf

    @property
    def last_observation(self) -> np.ndarray:
        """The newest [position; velocity] (2d,); zeros before the first."""
        return self._rows[self.count - 1, 1:].copy() if self.count else np.zeros(2 * self.d)

    def onset(self) -> float | None:
        """The first time (s) the hand's speed exceeds :data:`~comanip.estimation.people.endpoint_baselines.MOVING_SPEED`, or None."""
        if self._onset[0] != self.count:
            velocity = self.velocity
            self._onset = (self.count, detected_onset(self.t, np.sqrt((velocity * velocity).sum(axis=1)), MOVING_SPEED))
        return self._onset[1]

    def has_left(self, start_position: np.ndarray) -> bool:
        """Whether the hand has left its start (:func:`comanip.estimation.hand_rest.has_left`), looking only at the
        observations since the last call for the same start."""
        key = np.asarray(start_position, dtype=float).tobytes()
        if self._left[0] != key:
            self._left = (key, 0, False)
        _, checked, left = self._left
        if not left and checked < self.count:
            left = has_left(self.position[checked:], start_position)
        self._left = (key, self.count, left)
        return left


class Reach:
    """The reach under way: its start, the prior on its goal and the model's reach family.

    Args:
        family: the model's reach family for the goal width.
        start: the state at the start (nx,), at rest.
        prior_mean: g_bar (d,) m; prior_cov: P0 (d, d) m².
    """

    def __init__(self, family: ReachFamily, start: np.ndarray, prior_mean: np.ndarray, prior_cov: np.ndarray):
        self.family, self.model = family, family.model
        self.start = start
        self.start_position = start[:family.model.n].copy()
        self.prior_mean, self.prior_cov = prior_mean, prior_cov
        self.prior_precision = np.linalg.inv(prior_cov)

    def prediction(self, goal, *, order: int = 1, covariance: bool = True) -> ReachPrediction:
        """The plan from the start to ``goal`` (:meth:`ReachFamily.prediction`), or holding still for a goal at
        the start (the plan there: zero torque, no noise)."""
        if np.linalg.norm(np.asarray(goal) - self.start_position) == 0.0:
            model = self.model
            H, nx, d = model.H, model.state_size, model.d
            return ReachPrediction(mean=np.tile(self.start, (H + 1, 1)), cov=np.zeros((H + 1, nx, nx)),
                                   torque=np.zeros((H, model.n)), objective=0.0, mean_jacobian=np.zeros((H + 1, nx, d)),
                                   direction=np.eye(d)[0], curvature=np.zeros((H + 1, nx // model.n)),
                                   mixed=np.zeros((H + 1, nx // model.n)))
        return self.family.prediction(self.start_position, goal, order=order, covariance=covariance)

    def landed(self, fitted: "Explained", hand: np.ndarray) -> "Explained":
        """``fitted``, a goal and covariance fitted to the hand's movement, as an estimate: its goal moved along the
        line from the start through it up to the ``hand``'s (d,) m projection on that line when the hand is
        farther along (a hand that has moved on is not heading for a goal behind it), and combined with the
        prior."""
        goal, covariance = fitted.goal, fitted.covariance
        offset = goal - self.start_position
        distance = float(np.linalg.norm(offset))
        if distance > 0:
            along = float((hand - self.start_position) @ offset) / distance
            goal = goal + max(along - distance, 0.0) * offset / distance
        combined = np.linalg.inv(np.linalg.inv(covariance) + self.prior_precision)
        goal = combined @ (np.linalg.solve(covariance, goal) + self.prior_precision @ self.prior_mean)
        return replace(fitted, goal=goal, covariance=combined)


class Verdict(str, Enum):
    """What an explanation says of the hand so far."""

    EXPLAINS = "explains"
    """It explains the hand: its goal is the estimate."""
    UNDECIDED = "undecided"
    """It cannot tell yet (no movement seen, a fit that does not pin the goal yet): asked again next update."""
    MISFITS = "misfits"
    """The hand does not move as it says, now."""
    RULED_OUT = "ruled_out"
    """It is out for the rest of the reach (:class:`~comanip.estimation.online.explanations.vetoed.Vetoed`)."""

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class Explained:
    """One explanation's account of the hand so far."""

    goal: np.ndarray
    """Goal (d,), m."""
    covariance: np.ndarray
    """Its covariance (d, d), m²."""
    verdict: Verdict
    """Whether it explains the hand (else the next explanation is asked), and if not, why not."""
    message: str
    """What it found: why it explains the hand, or why not."""
    status: Status | EstimateStatus | None = None
    """The estimate's status when this explanation gives it (verdict EXPLAINS); None otherwise."""
    iterations: int = 0
    """Newton iterations spent."""
    misfit: float | None = None
    """How far the hand is from this explanation, in its own measure (None: not measured)."""
    timing: ReachTiming | None = None
    """When the reach moves, where this explanation says (the estimate's predicted reach is played at it);
    None: at the model's own pace from t = 0."""
    contestable: bool = True
    """Whether a veto may rule it out (:mod:`~comanip.estimation.online.explanations.vetoed`); False where no other
    explanation can do better, e.g. beyond the reach family's distances or a person's hand speeds."""

    def __post_init__(self):
        if (self.verdict is Verdict.EXPLAINS) != (self.status is not None):
            raise ValueError(f"an explanation that explains the hand gives the estimate's status, and only one that does; "
                             f"got verdict {self.verdict} with status {self.status}")

    @property
    def explains(self) -> bool:
        """Whether its verdict is :attr:`Verdict.EXPLAINS`."""
        return self.verdict is Verdict.EXPLAINS

    @classmethod
    def explaining(cls, goal, covariance, status: Status | EstimateStatus, message: str, **fields) -> "Explained":
        """An account that explains the hand with ``goal`` (d,) m, ``covariance`` (d, d) m² and ``status``."""
        return cls(goal, covariance, Verdict.EXPLAINS, message, status, **fields)

    @classmethod
    def not_explaining(cls, reach: "Reach", verdict: Verdict, message: str, **fields) -> "Explained":
        """An account that does not explain the hand (``verdict`` other than EXPLAINS), with the reach's prior
        as its goal unless ``fields`` give one."""
        goal, covariance = fields.pop("goal", reach.prior_mean), fields.pop("covariance", reach.prior_cov)
        return cls(goal, covariance, verdict, message, **fields)


class Explanation(Protocol):
    """An account of the hand's movement (module docstring)."""

    def reset(self, reach: Reach) -> None:
        """Start a new reach."""

    def explain(self, hand: HandTrace, latest: OnlineEstimate | None) -> Explained:
        """The goal this explanation gives for the observations so far; ``latest`` is the estimator's last
        estimate (None before the first)."""


class GridPosition(NamedTuple):
    """Where a time falls on the planning grid."""

    step: int
    """The step i ≤ H at or before it."""
    fraction: float
    """The fraction of a step (in [0, 1]) it lies after t_i."""


def grid_position(time_s: float, h: float, H: int) -> GridPosition:
    """Where time_s (s, ≥ 0) falls on the grid of step h (s); times at or after the horizon H·h read as (H, 0)."""
    grid = time_s / h
    before = min(H, int(math.floor(grid * (1 + 1e-9))))
    return GridPosition(before, 0.0 if before == H else min(max(grid - before, 0.0), 1.0))
