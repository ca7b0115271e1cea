"""Expected reward of hitting a goal of width w (SPEC §3, paper eq. 7 and appendix).

The goal is a Gaussian g ~ N(g_bar, W); the end effector is x ~ N(mu_x, Sigma_x). The expected reward is
the density of their difference at zero,

    R(mu_x, Sigma_x) = exp(-½ (mu_x - g)^T (Sigma_x + W)^-1 (mu_x - g)) / sqrt(det(2π (Sigma_x + W)))

in m^-d. W (d, d) comes from the width w (m): ``std`` (default) W = w² I, the width as the goal's standard
deviation; ``cov`` W = w I, the width used as the covariance itself (the paper's notation read literally).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

GOAL_COVARIANCE_FORMS = ("std", "cov")


def check_goal_covariance_form(form: str) -> str:
    if form not in GOAL_COVARIANCE_FORMS:
        raise ValueError(f"goal_covariance must be one of {GOAL_COVARIANCE_FORMS}, got {form!r}")
    return form


def goal_covariance(width, d: int, form: str = "std"):
    """W (d, d) from the goal width w (m): w² I (``std``) or w I (``cov``). Works on CasADi and NumPy scalars."""
    check_goal_covariance_form(form)
    scale = width**2 if form == "std" else width
    if isinstance(width, (ca.SX, ca.MX)):
        return scale * ca.DM.eye(d)
    return float(scale) * np.eye(d)


def expected_reward(mu_x, Sigma_x, goal, W):
    """Closed-form E[R] (m^-d): mu_x (d,), Sigma_x (d, d), goal (d,), W (d, d), CasADi or NumPy.

    Returns a CasADi expression for symbolic input and a float for numeric input.
    """
    symbolic = any(isinstance(v, (ca.SX, ca.MX)) for v in (mu_x, Sigma_x, goal, W))
    if symbolic:
        S = Sigma_x + W
        e = mu_x - goal
        d = e.shape[0]
        return ca.exp(-0.5 * ca.dot(e, ca.solve(S, e))) / ca.sqrt((2 * ca.pi) ** d * ca.det(S))
    S = np.asarray(Sigma_x, dtype=float) + np.asarray(W, dtype=float)
    e = np.asarray(mu_x, dtype=float) - np.asarray(goal, dtype=float)
    return float(np.exp(-0.5 * e @ np.linalg.solve(S, e)) / np.sqrt(np.linalg.det(2 * np.pi * S)))
