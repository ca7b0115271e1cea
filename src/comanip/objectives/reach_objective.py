"""The minimised objective (SPEC §4, paper eq. 8–10): discounted expected reward, negated, plus effort.

    J(tau_{0:H-1}) = Σ_{i=0..H} -w_i R(mu_x,i, Sigma_x,i) + nu Σ_{i=0..H-1} ||tau_i||²

with w_i the discount weights (gamma^i by default) and nu (m^-d per (N·m)²) the effort weight.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from comanip.objectives.reward import GoalReward


def reach_objective(ee_means, ee_covs, torques, goal, width, weights, nu, reward: GoalReward):
    """J for task-space beliefs ee_means[i] (d,), ee_covs[i] (d, d), i = 0..H, and torques[i] (n,), i < H,
    to a goal (d,) of width w (m) under the model's ``reward`` (:class:`GoalReward`).

    Accepts sequences of CasADi expressions (returns an expression) or NumPy arrays (returns a float).
    """
    total = sum(-w * reward.expected(m, S, goal, width) for w, m, S in zip(weights, ee_means, ee_covs))
    effort = sum(ca.sumsqr(tau) if isinstance(tau, (ca.SX, ca.MX)) else float(np.sum(np.square(tau))) for tau in torques)
    return total + nu * effort


def stopping_cost(mean_velocity, velocity_cov, stop_weight: float):
    """stop_weight · E||qdot||² = stop_weight (||mu_qdot||² + tr Sigma_qdot) of the final state (the
    model's stopping requirement, which the planner scales by |J_best|): mean_velocity (n,), velocity_cov (n, n),
    CasADi or NumPy."""
    if isinstance(mean_velocity, (ca.SX, ca.MX)):
        return stop_weight * (ca.sumsqr(mean_velocity) + ca.trace(velocity_cov))
    return stop_weight * float(np.sum(np.square(mean_velocity)) + np.trace(velocity_cov))
