"""The minimised objective (SPEC §4, paper eq. 8–10): discounted expected reward, negated, plus effort.

    J(tau_{0:H-1}) = Σ_{i=0..H} -w_i R(mu_x,i, Sigma_x,i) + nu Σ_{i=0..H-1} ||tau_i||²

with w_i the discount weights (gamma^i by default) and nu (m^-d per (N·m)²) the effort weight.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from comanip.objectives.reward import expected_reward


def reach_objective(ee_means, ee_covs, torques, goal, W, weights, nu):
    """J for task-space beliefs ee_means[i] (d,), ee_covs[i] (d, d), i = 0..H, and torques[i] (n,), i < H.

    Accepts sequences of CasADi expressions (returns an expression) or NumPy arrays (returns a float).
    """
    reward = sum(-w * expected_reward(m, S, goal, W) for w, m, S in zip(weights, ee_means, ee_covs))
    effort = sum(ca.sumsqr(tau) if isinstance(tau, (ca.SX, ca.MX)) else float(np.sum(np.square(tau))) for tau in torques)
    return reward + nu * effort
