"""The prior over the goal of a reach: a mean g_bar (d,) m and its own uncertainty, a covariance (d, d) m².

``prior_std`` says how rough the guess is:

- ``None``: the weak default, :data:`DEFAULT_PRIOR_STD` (1 m) on every axis. It keeps an estimate finite when
  the observations say little about some direction, and cannot pull the estimate from an exact observation
  by more than about a millimetre on the paper presets (tests/test_online_estimation.py measures it).
- a number s > 0 (m): s² I; a sequence of d numbers (m): diag(s_1², ..., s_d²).
- ``"width"`` (:data:`PAPER_PRIOR`): the paper's weighting, W from the goal width (W = w² I by default; the
  model's ``goal_covariance`` form): the prior is then as uncertain as the goal is wide, which dominates the
  observation early in a slow reach (issue 12: Cartesian estimates 38–55 % short for a prior 0.2–0.45 m off).
"""

from __future__ import annotations

import math

import numpy as np

from comanip.objectives.reward import goal_covariance

#: Standard deviation (m) of the default, weak prior.
DEFAULT_PRIOR_STD = 1.0
#: The ``prior_std`` value that asks for the paper's weighting (W from the goal width).
PAPER_PRIOR = "width"


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
