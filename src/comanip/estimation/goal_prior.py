"""The prior over the goal of a reach: a mean g_bar (d,) m and its own uncertainty, a covariance (d, d) m².

``prior_std`` says how rough the guess is:

- ``None``: the weak default, :data:`DEFAULT_PRIOR_STD` (10 m) on every axis. It keeps an estimate finite when
  the observations say little about some direction. It must be this weak because an early observation says
  little about the distance: on the Cartesian preset a state seen exactly at 0.165 s (step 3 of a ~1 s reach)
  leaves the goal's distance uncertain by 0.3–0.7 m (one standard deviation, the model's own motor noise),
  so a 1 m prior 0.2–0.45 m off still pulls that estimate by up to 3 % of the distance; the 10 m default by
  at most 0.2 % (tests/estimation/online/test_online_estimator.py).
- a number s > 0 (m): s² I; a sequence of d numbers (m): diag(s_1², ..., s_d²).
- ``"width"`` (:data:`PAPER_PRIOR`): the paper's weighting, W from the goal width (W = w² I by default; the
  model's ``goal_covariance`` form): the prior is then as uncertain as the goal is wide, which dominates the
  observation early in a slow reach (how much: docs/results/calibration.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.objectives.reward import goal_covariance

DEFAULT_PRIOR_STD = 10.0
"""Standard deviation (m) of the default, weak prior."""
PAPER_PRIOR = "width"
"""The ``prior_std`` value that asks for the paper's weighting (W from the goal width)."""


def prior_covariance(prior_std, model, width: float) -> np.ndarray:
    """The prior's covariance (d, d) m² from ``prior_std`` (module docstring) for a ReachingModel; ``width``
    (m) and the model's goal-covariance form give ``"width"``. Raises ValueError naming ``prior_std``
    for anything else."""
    d = model.d
    if prior_std is None:
        return DEFAULT_PRIOR_STD**2 * np.eye(d)
    if isinstance(prior_std, str):
        if prior_std != PAPER_PRIOR:
            raise ValueError(f"prior_std must be a positive number or {d} of them (m), None (the weak default, "
                             f"{DEFAULT_PRIOR_STD:g} m) or {PAPER_PRIOR!r} (the paper's W from the width), got {prior_std!r}")
        return goal_covariance(width, d, model.goal_covariance, model.effective_k)
    try:
        values = np.asarray(prior_std, dtype=float)
    except (TypeError, ValueError):
        values = np.array([math.nan])
    if values.ndim == 0:
        values = np.full(d, float(values))
    if values.shape != (d,) or not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise ValueError(f"prior_std must be a positive number or {d} of them (m), None (the weak default, "
                         f"{DEFAULT_PRIOR_STD:g} m) or {PAPER_PRIOR!r} (the paper's W from the width), got {prior_std!r}")
    return np.diag(values**2)


@dataclass(frozen=True)
class GoalPrior:
    """A Gaussian prior over the goal: N(mean, covariance)."""

    mean: np.ndarray
    """g_bar (d,), m."""
    covariance: np.ndarray
    """(d, d), m² (:func:`prior_covariance`)."""

    @property
    def precision(self) -> np.ndarray:
        """covariance^-1 (d, d), m^-2."""
        return np.linalg.inv(self.covariance)
