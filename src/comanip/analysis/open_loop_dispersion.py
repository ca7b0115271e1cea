"""Endpoint dispersion by open-loop Monte Carlo of a plan's torques (paper Fig. 4, docs/formulation.md §6).

The planned torques tau_{0:H-1} are executed as (I + E_i) tau_i with E_i drawn as the model's noise form
says (:func:`comanip.belief.sample_trajectories`), without feedback. At the plan's movement time the hand
positions of the samples are split into the component along the movement (start → goal) and across it;
their standard deviations, a Gaussian fitted to the across offsets and the hit rate (hand within w of the
goal) are reported beside the plan's own closed-form prediction J Sigma_qq J^T at the same step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import norm

from comanip.analysis.speed_profile import speed_metrics
from comanip.arguments import as_count
from comanip.belief import sample_trajectories
from comanip.model import ReachingModel
from comanip.planning.plan import Plan


@dataclass
class EndpointDispersion:
    """Spread of the hand at the movement time over open-loop executions. N samples, T = H+1 steps, d dims."""

    width: float
    """Goal width w (m)."""
    time: float
    """Time at which the endpoints are taken (s): the first step at or after the plan's movement time."""
    step: int
    """Index of that step."""
    along_std: float
    """Monte Carlo standard deviation of the hand along the movement (m)."""
    across_std: float
    """Monte Carlo standard deviation across the movement (m), along the ``across`` axis."""
    predicted_along_std: float
    """The plan's closed-form standard deviation along the movement at that step (m)."""
    predicted_across_std: float
    """The plan's closed-form standard deviation along the ``across`` axis (m)."""
    across_fit_mean: float
    """Mean of the Gaussian fitted (maximum likelihood) to the across offsets (m)."""
    across_fit_std: float
    """Standard deviation of that Gaussian (m)."""
    hit_rate: float
    """Fraction of samples whose hand is within w of the goal."""
    along: np.ndarray
    """Unit vector (d,) from start to goal."""
    across: np.ndarray
    """Unit vector (d,) across the movement (for d = 2, along rotated by +90°; else the direction of
    largest predicted spread perpendicular to the movement)."""
    across_offsets: np.ndarray
    """Signed offsets (N,) of the sampled hands from the goal along ``across`` (m)."""
    paths: np.ndarray
    """Sampled hand paths (N, T, d), m."""

    def summary(self) -> dict:
        """The scalar fields, for reports."""
        names = ("width", "time", "step", "along_std", "across_std", "predicted_along_std", "predicted_across_std",
                 "across_fit_mean", "across_fit_std", "hit_rate")
        return {name: getattr(self, name) for name in names} | {"samples": int(len(self.paths))}


def endpoint_dispersion(model: ReachingModel, plan: Plan, n_samples: int, rng: np.random.Generator) -> EndpointDispersion:
    """Open-loop Monte Carlo (n_samples ≥ 2 executions) of plan.torque under model's noise; see the module doc."""
    as_count("n_samples", n_samples, 2)
    body = model.body
    states = sample_trajectories(body, model.h, model.kappa, plan.start, plan.torque, n_samples, rng, model.noise)
    kinematics = body.kinematics_function.map(n_samples * states.shape[1])
    q = states[:, :, : model.n].reshape(-1, model.n)
    paths = np.asarray(kinematics(q.T)[0]).T.reshape(n_samples, states.shape[1], model.d)

    metrics = speed_metrics(plan.t, plan.ee_speed)
    step = len(plan.t) - 1 if not metrics.settled else int(min(np.searchsorted(plan.t, metrics.movement_time - 1e-12), len(plan.t) - 1))
    along = plan.goal - plan.ee_mean[0]
    along = along / np.linalg.norm(along)
    across = _across_axis(along, plan.ee_cov[step])

    offsets = paths[:, step] - plan.goal
    across_offsets = offsets @ across
    fit_mean, fit_std = norm.fit(across_offsets)
    return EndpointDispersion(
        width=plan.width, time=float(plan.t[step]), step=step,
        along_std=float(np.std(offsets @ along, ddof=1)), across_std=float(np.std(across_offsets, ddof=1)),
        predicted_along_std=float(np.sqrt(along @ plan.ee_cov[step] @ along)),
        predicted_across_std=float(np.sqrt(across @ plan.ee_cov[step] @ across)),
        across_fit_mean=float(fit_mean), across_fit_std=float(fit_std),
        hit_rate=float(np.mean(np.linalg.norm(offsets, axis=1) <= plan.width)),
        along=along, across=across, across_offsets=across_offsets, paths=paths)


def _across_axis(along: np.ndarray, ee_cov: np.ndarray) -> np.ndarray:
    if len(along) == 2:
        return np.array([-along[1], along[0]])
    project = np.eye(len(along)) - np.outer(along, along)
    _, vectors = np.linalg.eigh(project @ ee_cov @ project)
    return vectors[:, -1]
