"""The likelihood of one recorded trial under a plan's predicted end-effector mean and covariance.

A trial's first sample is its start: the condition's plan, moved by the trial's start offset o (first
sample minus the condition's start, see :mod:`comanip.fitting.conditions`), predicts every later sample.
With measurement noise e ~ N(0, sigma_obs² I) on every sample, the offset carries the first sample's
noise into the prediction, so a later sample at t_k is predicted as

    x(t_k) ~ N(m(t_k) + o, S(t_k) + 2 sigma_obs² I)

with m and S the plan's end-effector mean and covariance interpolated linearly between its steps. The
first sample itself is not scored (it is matched exactly by construction). sigma_obs keeps the
likelihood finite early in the reach, where the plan's position covariance is still zero.

The samples of one trial are treated as independent given the plan: the negative log-likelihood of a
trial is the sum over its samples. This is a pseudo- (composite) likelihood. Its maximum is still a
consistent estimate (every sample's marginal distribution is the model's), but neighbouring samples of a
real trajectory are strongly correlated, so its curvature overstates the information in the data and the
plain Laplace standard errors come out too small; :mod:`comanip.fitting.uncertainty` corrects them.
Samples after the plan's horizon (t > H·h) are left out.
"""

from __future__ import annotations

import numpy as np

from comanip.recordings.trial_files import Trial
from comanip.planning.plan import Plan


def interpolate(grid: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """values (T, ...) given at increasing grid times (T,), s, linearly interpolated at times (K,) within
    [grid[0], grid[-1]] -> (K, ...)."""
    i = np.clip(np.searchsorted(grid, times, side="right") - 1, 0, len(grid) - 2)
    w = ((times - grid[i]) / (grid[i + 1] - grid[i])).reshape((-1,) + (1,) * (values.ndim - 1))
    return (1 - w) * values[i] + w * values[i + 1]


def scored_samples(plan: Plan, trial: Trial) -> np.ndarray:
    """Mask (K,) of the samples the likelihood scores: after the first, at or before the plan's last step."""
    mask = trial.t <= plan.t[-1] * (1 + 1e-12)
    mask[0] = False
    return mask


def predicted_mean(plan: Plan, trial: Trial, offset: np.ndarray) -> np.ndarray:
    """The model's mean hand position (K', d), m, at the trial's scored samples."""
    return interpolate(plan.t, plan.ee_mean, trial.t[scored_samples(plan, trial)]) + offset


def trial_nll(plan: Plan, trial: Trial, offset: np.ndarray, sigma_obs: float) -> float:
    """Negative log-likelihood (nats) of the trial's scored samples, treated as independent.

    plan: the condition's plan; offset (d,), m: trial start minus condition start; sigma_obs: m.
    Returns inf when the plan is not finite.
    """
    keep = scored_samples(plan, trial)
    times, d = trial.t[keep], trial.position.shape[1]
    residual = trial.position[keep] - predicted_mean(plan, trial, offset)
    cov = interpolate(plan.t, plan.ee_cov, times) + 2 * sigma_obs**2 * np.eye(d)
    if not (np.all(np.isfinite(residual)) and np.all(np.isfinite(cov))):
        return np.inf
    cov = 0.5 * (cov + np.swapaxes(cov, 1, 2))
    factor = np.linalg.cholesky(cov)
    z = np.linalg.solve(factor, residual[..., None])[..., 0]
    log_det = 2 * np.log(np.diagonal(factor, axis1=1, axis2=2)).sum()
    return float(0.5 * np.sum(z**2) + 0.5 * log_det + 0.5 * z.size * np.log(2 * np.pi))
