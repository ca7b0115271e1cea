"""Observations of a reach in progress: checked states, their times, the plan steps they belong to, and
their likelihood under a plan's belief.

An observation is a state s_o = [q; qdot] (2n,) measured at a time t_o (s) after the reach started. The plan
lives on the grid t_i = i·h, so an observation belongs to step n_o = floor(t_o / h), the nearest *earlier*
step (paper Section V-C: "the discrete time-step closest to the continuous time of measurement
n_o = floor(t_o / h)"). A time that is a multiple of h up to rounding (e.g. 0.2 s on h = 0.02 s, where
0.2/0.02 = 9.999…) maps to that multiple: the division is given a relative slack of 1e-9 before flooring.

What an observation can tell about the goal depends on its step (forward Euler, docs/formulation.md §2):

- n_o ≥ 2 (t_o ≥ 2h): the whole state depends on the torques; an estimate holds its plan to all of it.
- n_o = 1 (h ≤ t_o < 2h): q_1 = q_0 + h qdot_0 is fixed by the start, and only the velocity qdot_1 (through
  tau_0) depends on the torques: an estimate holds its plan to the observed velocity only, and reports
  the position's mismatch (``GoalEstimate.observation_residual``).
- n_o = 0 (0 < t_o < h): the state at step 0 is the start itself; the observation says nothing about the
  goal. An estimate is then the plan to the prior goal (status 'uninformative'), and without a prior goal
  there is nothing to return (ValueError).
"""

from __future__ import annotations

import math

from typing import NamedTuple

import numpy as np

from comanip.arguments import as_matrix, as_positive, as_vector
from comanip.model import ReachingModel
from comanip.planning.plan import Plan

OBSERVATION_STD = (1e-3, 1e-2)
"""Default observation-noise floor: standard deviation of a measured position (m or rad) and velocity (m/s or
rad/s). About what motion capture or joint encoders with differentiated velocity deliver."""

_GRID_SLACK = 1e-9
"""Relative slack on t/h so that times on the grid are not floored one step early by rounding."""


def observation_step(model: ReachingModel, t_obs, *, allow_start: bool = False, name: str = "t_obs") -> int:
    """Plan step n_o = floor(t_obs / h) of an observation at t_obs (s).

    t_obs must lie in (0, H·h) (an estimate; the module docstring says what each step can tell), or in
    [0, H·h] with ``allow_start`` (a posterior, which scores states rather than constraining them).
    Anything else raises ValueError naming ``name``.
    """
    if isinstance(t_obs, bool) or not isinstance(t_obs, (int, float, np.integer, np.floating)) or not math.isfinite(t_obs):
        raise ValueError(f"{name} must be a finite time in s, got {t_obs!r}")
    t_obs = float(t_obs)
    horizon = model.H * model.h
    inside = (0.0 <= t_obs <= horizon) if allow_start else (0.0 < t_obs < horizon)
    if not inside:
        interval = f"[0, {horizon:g}]" if allow_start else f"(0, {horizon:g})"
        raise ValueError(f"{name} must lie in {interval} s (the model's horizon H·h = {model.H}·{model.h:g} s), got {t_obs:g}")
    return min(model.H, int(math.floor(t_obs / model.h * (1.0 + _GRID_SLACK))))


def observed_rows(model: ReachingModel, step: int) -> np.ndarray:
    """Entries of the state [q; qdot] (2n,) the torques can move at ``step``: all from step 2, the
    velocity at step 1, none at step 0 (module docstring)."""
    n = model.n
    return np.arange(2 * n) if step >= 2 else np.arange(n, 2 * n) if step == 1 else np.zeros(0, dtype=int)


def observed_state(model: ReachingModel, state, name: str = "observed") -> np.ndarray:
    """state as a finite (2n,) array [q; qdot], else ValueError naming ``name``."""
    return as_vector(name, state, 2 * model.n, "state [q; qdot] in m and m/s, or rad and rad/s")


class ObservedSequence(NamedTuple):
    """Checked, time-ordered observations."""

    states: np.ndarray
    """(K, 2n) [q; qdot]."""
    times: np.ndarray
    """(K,) s."""
    steps: np.ndarray
    """(K,) the grid step at or before each time."""


def observed_sequence(model: ReachingModel, states, times) -> ObservedSequence:
    """Checked time-ordered observations: states (K, 2n), times (K,) s in [0, H·h] -> (states, times, steps (K,)).

    A single observation may be given as a state (2n,) and a scalar time.

    Raises ValueError naming ``observed_states`` or ``times`` on a wrong shape, NaN, an empty sequence,
    decreasing times or a time outside the horizon.
    """
    try:
        times = np.atleast_1d(np.asarray(times, dtype=float))
    except (TypeError, ValueError):
        raise ValueError(f"times must be a 1-D array of observation times (s), got {times!r}") from None
    if times.ndim != 1 or times.size == 0:
        raise ValueError(f"times must be a non-empty 1-D array of observation times (s), got shape {np.shape(times)}")
    if np.ndim(states) == 1 and times.size == 1:
        states = np.reshape(states, (1, -1))
    states = as_matrix("observed_states", states, (times.size, 2 * model.n),
                       "one state [q; qdot] per observation time, m and m/s or rad and rad/s")
    if np.any(np.diff(times) < 0):
        raise ValueError(f"times must be non-decreasing (s), got {times.tolist()}")
    steps = np.array([observation_step(model, t, allow_start=True, name="times") for t in times])
    return ObservedSequence(states, times, steps)


def observation_covariance(observation_std, n: int) -> np.ndarray:
    """R (2n, 2n) = diag(sigma_q² I_n, sigma_qdot² I_n) from observation_std = (sigma_q, sigma_qdot)."""
    try:
        sigma_q, sigma_qdot = observation_std
    except (TypeError, ValueError):
        raise ValueError(f"observation_std must be a pair (position std, velocity std) in state units, got {observation_std!r}") from None
    sigma_q = as_positive("observation_std[0]", sigma_q, "m or rad")
    sigma_qdot = as_positive("observation_std[1]", sigma_qdot, "m/s or rad/s")
    return np.diag(np.r_[np.full(n, sigma_q**2), np.full(n, sigma_qdot**2)])


def joint_state_covariance(plan: Plan, steps: np.ndarray, step_jacobians) -> np.ndarray:
    """Covariance (2nK, 2nK) of the states at non-decreasing steps (K,) under the plan's open-loop belief.

    ``step_jacobians(mu_i, tau_i) -> (f, A_i, B_i)`` is the body's linearised step; block (j, k), j ≥ k, is
    A_{n_j - 1} ⋯ A_{n_k} Sigma_{n_k}.
    """
    n2 = plan.mean.shape[1]
    K = len(steps)
    A = {}
    C = np.zeros((K * n2, K * n2))
    for k, n_k in enumerate(steps):
        block, at = plan.cov[n_k], n_k
        C[k * n2:(k + 1) * n2, k * n2:(k + 1) * n2] = block
        for j in range(k + 1, K):
            for i in range(at, steps[j]):
                if i not in A:
                    A[i] = np.asarray(step_jacobians(plan.mean[i], plan.torque[i])[1])
                block = A[i] @ block
            at = steps[j]
            C[j * n2:(j + 1) * n2, k * n2:(k + 1) * n2] = block
            C[k * n2:(k + 1) * n2, j * n2:(j + 1) * n2] = block.T
    return C


def prefix_log_likelihoods(plan: Plan, states: np.ndarray, steps: np.ndarray, R: np.ndarray, step_jacobians) -> np.ndarray:
    """log N(s_1..k; plan belief + R) for every prefix k = 1..K: states (K, 2n), steps (K,) -> (K,)."""
    n2 = states.shape[1]
    residual = (states - plan.mean[steps]).ravel()
    C = joint_state_covariance(plan, steps, step_jacobians) + np.kron(np.eye(len(steps)), R)
    out = np.zeros(len(steps))
    for k in range(len(steps)):
        m = (k + 1) * n2
        L = np.linalg.cholesky(C[:m, :m])
        z = np.linalg.solve(L, residual[:m])
        out[k] = -0.5 * (z @ z) - np.sum(np.log(np.diag(L))) - 0.5 * m * np.log(2 * np.pi)
    return out
