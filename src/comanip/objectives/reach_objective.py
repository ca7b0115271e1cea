"""The minimised objective (docs/formulation.md §4, paper eq. 8–10): discounted expected reward, negated, plus effort.

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


def velocity_cost(velocity_means, velocity_covs, stop_weight, joint_velocity_weight):
    """The model's speed cost before its |J_best| scale (docs/formulation.md §4 options ``stop_weight`` c_s and
    ``joint_velocity_weight`` c_v), over the velocity beliefs of steps i = 1..H:

        c_s E||qdot_H||² + c_v (1/H) Σ_{i=1..H} E||qdot_i||²,   E||qdot_i||² = ||mu_qdot,i||² + tr Sigma_qdot,i.

    velocity_means[i] (n,) and velocity_covs[i] (n, n), i = 0..H-1 for steps 1..H, CasADi or NumPy (the weights
    may be CasADi symbols); returns an expression or a float. Speeds in rad/s or m/s, weights in (s/rad)² or (s/m)².
    """
    symbolic = isinstance(velocity_means[0], (ca.SX, ca.MX))
    energies = [(ca.sumsqr(m) + ca.trace(S)) if symbolic else float(np.sum(np.square(m)) + np.trace(S))
                for m, S in zip(velocity_means, velocity_covs)]
    return stop_weight * energies[-1] + joint_velocity_weight * sum(energies) / len(energies)
