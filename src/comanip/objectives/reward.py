"""Expected reward of hitting a goal of width w (docs/formulation.md §3, paper eq. 7 and appendix).

The goal is a Gaussian g ~ N(g_bar, W); the end effector is x ~ N(mu_x, Sigma_x). The expected reward is
the density of their difference at zero,

    R(mu_x, Sigma_x) = exp(-½ (mu_x - g)^T (Sigma_x + W)^-1 (mu_x - g)) / sqrt(det(2π (Sigma_x + W)))

in m^-d. W (d, d) comes from the width w (m): ``std`` (default) W = w² I, the width as the goal's standard
deviation; ``cov`` W = w I, the width used as the covariance itself (the paper's notation read literally);
``effective`` W = (2w/k)² I, the goal's full width 2w spanning k standard deviations (k = 4.133 is the
effective-width convention of Fitts studies).

The ``hit`` reward reads w as the radius of the goal ball (paper eq. 1, R = 1 inside, 0 outside) and
replaces the indicator by a smooth flat-topped kernel of the distance r = ||x - g||,

    K(r) = Q(m + 1, r² / (2 s²)) = exp(-u) Σ_{j=0..m} u^j / j!,   u = r² / (2 s²),

the regularised upper incomplete gamma function: 1 - O(r^(2m+2)) near the centre, 1/2 at r = w (s is set so),
falling off beyond. Its expectation over x ~ N(mu_x, Sigma_x) is a finite closed form: with
F(t) = E[exp(-t u)] = det(I + t Sigma_x / s²)^-1/2 exp(-t e^T (s² I + t Sigma_x)^-1 e / 2), e = mu_x - g,

    E[K] = Σ_{j=0..m} (-1)^j F^(j)(1) / j!,

the derivatives of F taken symbolically (CasADi). With m = 4 it is the probability of a hit up to the soft
edge: 0.98 (kernel) against 0.996 (ball) for a centred hand with sigma = 0.3 w in 2-D, 0.81 against 0.85
at sigma = 0.4 w, 0.5 w off centre (tests/objectives/test_reward.py checks the closed form against Monte Carlo of the
kernel). It is dimensionless, at most 1, and saturates once the hand is surely inside the goal: unlike the
Gaussian overlap, precision beyond the goal's size earns nothing.
"""

from __future__ import annotations

from functools import cached_property

import casadi as ca
import numpy as np
from scipy.special import gammaincinv

GOAL_COVARIANCE_FORMS = ("std", "cov", "effective")
REWARD_FORMS = ("gaussian", "hit")
HIT_KERNEL_ORDER = 4
"""m of the hit kernel: higher is a sharper edge, at a much larger expression (m = 8: 30 times the nodes)."""
EFFECTIVE_WIDTH_K = 4.133
"""Standard deviations in the full width of a target under the effective-width convention (96 % inside)."""


def check_reward_form(form: str) -> str:
    if form not in REWARD_FORMS:
        raise ValueError(f"reward must be one of {REWARD_FORMS}, got {form!r}")
    return form


def check_goal_covariance_form(form: str) -> str:
    if form not in GOAL_COVARIANCE_FORMS:
        raise ValueError(f"goal_covariance must be one of {GOAL_COVARIANCE_FORMS}, got {form!r}")
    return form


def goal_variance(width, form: str = "std", effective_k: float = EFFECTIVE_WIDTH_K):
    """The variance c (m²) per axis of W = c I for a goal width w (m): w², w or (2w/k)² (see goal_covariance)."""
    check_goal_covariance_form(form)
    if form == "std":
        return width**2
    return width if form == "cov" else (2 * width / effective_k) ** 2


def goal_covariance(width, d: int, form: str = "std", effective_k: float = EFFECTIVE_WIDTH_K):
    """W (d, d) from the goal width w (m): w² I (``std``), w I (``cov``) or (2w/k)² I (``effective``).

    Works on CasADi and NumPy scalars."""
    scale = goal_variance(width, form, effective_k)
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


class GoalReward:
    """The per-step reward of one model's goal: R(mu_x, Sigma_x; g, w) and its peak, for either form.

    Args:
        d: task-space dimension.
        form: 'gaussian' (paper eq. 7, m^-d) or 'hit' (probability of a hand inside the ball of radius w,
            through the flat-topped kernel of this module's docstring; dimensionless).
        goal_covariance: how W is built from w for the Gaussian form (see :func:`goal_covariance`).
        effective_k: the number of standard deviations the full width 2w spans, for
            ``goal_covariance='effective'``.
    """

    def __init__(self, d: int, form: str = "gaussian", goal_covariance: str = "std", effective_k: float = EFFECTIVE_WIDTH_K):
        self.d, self.form = d, check_reward_form(form)
        self.goal_covariance_form, self.effective_k = check_goal_covariance_form(goal_covariance), effective_k

    @cached_property
    def hit_function(self) -> ca.Function:
        """``(e (d,), Sigma_x (d, d), w) -> E[K]`` of the hit form (:func:`hit_kernel_function`), built once per reward."""
        return hit_kernel_function(self.d)

    @classmethod
    def of(cls, model) -> "GoalReward":
        """The reward a :class:`comanip.ReachingModel` asks for."""
        return cls(model.d, model.reward, model.goal_covariance, model.effective_k)

    def covariance(self, width):
        """W (d, d) of the Gaussian reading of the goal (also the estimator's prior weight)."""
        return goal_covariance(width, self.d, self.goal_covariance_form, self.effective_k)

    def expected(self, mu_x, Sigma_x, goal, width):
        """E[R] for mu_x (d,), Sigma_x (d, d), goal (d,), width w (m): a CasADi expression or a float."""
        if self.form == "gaussian":
            return expected_reward(mu_x, Sigma_x, goal, self.covariance(width))
        if any(isinstance(v, (ca.SX, ca.MX)) for v in (mu_x, Sigma_x, goal, width)):
            return self.hit_function(mu_x - goal, Sigma_x, width)
        return float(self.hit_function(np.asarray(mu_x, float) - np.asarray(goal, float), np.asarray(Sigma_x, float), float(width)))

    def peak(self, width):
        """R of a noiseless hand on the goal: 1/sqrt(det(2π W)) (Gaussian) or 1 (hit); a CasADi expression of
        a symbolic width, a float of a number (the solvers ask for it at every Hessian)."""
        if self.form == "hit":
            return width**0  # 1, of width's type
        if isinstance(width, (ca.SX, ca.MX)):
            return 1 / ca.sqrt(ca.det(2 * ca.pi * self.covariance(width)))
        return (2 * np.pi * goal_variance(float(width), self.goal_covariance_form, self.effective_k)) ** (-self.d / 2)


def hit_kernel_function(d: int) -> ca.Function:
    """``(e (d,), Sigma_x (d, d), w) -> E[K]`` of the flat-topped hit kernel (module docstring), for a task space of
    dimension d."""
    m = HIT_KERNEL_ORDER
    e, Sigma, width, t = ca.SX.sym("e", d), ca.SX.sym("Sigma", d, d), ca.SX.sym("w"), ca.SX.sym("t")
    s2 = width**2 / (2 * float(gammaincinv(m + 1, 0.5)))  # K(w) = 1/2
    A = s2 * ca.SX.eye(d) + t * Sigma
    F = ca.exp(-0.5 * t * ca.dot(e, ca.solve(A, e))) / ca.sqrt(ca.det(A / s2))
    total, derivative, factorial = 0, F, 1.0
    for j in range(m + 1):
        total += (-1) ** j * derivative / factorial
        derivative, factorial = ca.jacobian(derivative, t), factorial * (j + 1)
    return ca.Function("expected_hit", [e, Sigma, width], [ca.substitute(total, t, 1.0)], ["e", "Sigma_x", "w"], ["R"])
