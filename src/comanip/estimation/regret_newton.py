"""Goal estimation as inverse planning: the goal whose plan the observed state departs from least.

Notation as in :mod:`comanip.planning.reach_problem`: torques tau (H·n,) stacked step by step, start s_0,
goal g (d,) m, width w (m), W = W(w) (d, d), the SPEC §4 objective J(tau, g), and the mean state mu_no(tau)
at the observed step n_o. Objectives are divided by the planner's normaliser |J_best(w)| (the best
attainable J), so the numbers the solver sees lie in about [-1, 0] for every width.

**Why not eq. 11 as printed.** The paper (Section V-C, SPEC §7) estimates the goal by

    min_{tau, g}  J(tau, g) + (g - g_bar)^T W^-1 (g - g_bar)   s.t.  mu_0 = s_0,  mu_no(tau) = s_o.

Minimising J over g as well favours goals that are cheap to reach from the observation, not the goal the
person is heading to: the reward earned near the start and the shorter remaining reach make a nearby goal
score better. Observing a planar plan at 0.2 s and solving eq. 11 from the true goal puts the estimate at
0.5–0.85 of the true distance, and sometimes on the start itself; on the Cartesian preset (observed at
0.165 s) at 0.07–0.16 of it. The plan to the true goal is not even a stationary point: dJ/dg ≠ 0 there.

**Regret.** Subtract what reaching g costs without the observation, V*(g) = min_tau J(tau, g) (the plan):

    min_g  R(g) = Jc(g) - V*(g) + (g - g_bar)^T W^-1 (g - g_bar),    Jc(g) = min_{tau: mu_no(tau) = s_o} J(tau, g).

Jc ≥ V*, with equality exactly when the plan to g passes through s_o: the regret is the extra cost the
observation forces on a person heading to g, zero at the goal a plan was made for, so an exact observation
of a plan gives back its goal. It keeps eq. 11's objective and constraint and only removes the term V*(g)
that biases it; the regulariser is the paper's.

**First-order conditions.** By the envelope theorem dJc/dg = dJ/dg at tau_c and dV*/dg = dJ/dg at tau_s, so
the optimum is a root of

    F1 = grad_tau J(tau_c, g) + A^T lam        (H·n)   tau_c optimal subject to the observation
    F2 = mu_no(tau_c) - s_o                    (2n)    ... which it passes through
    F3 = grad_tau J(tau_s, g)                  (H·n)   tau_s the unconstrained plan to g
    F4 = grad_g J(tau_c, g) - grad_g J(tau_s, g) + 2 P (g - g_bar)   (d)

with A = dmu_no/dtau and P = W^-1 / |J_best| (zero without a prior). Only second derivatives of J appear,
the Hessians a plan's solver uses anyway: Newton's method on F costs two of them per iteration. No NLP
solver takes a value function as an objective, so the iteration is written out here; IPOPT (through the
planner) provides its starting point. Block elimination reduces each Newton step to a d×d system in the
goal whose matrix is the regret's Hessian d²R/dg²; where that is not positive definite (far from the
optimum) its eigenvalues are mirrored so the step still descends. A trust region on the goal step, judged
by the regret the inner problems' quadratic models predict, keeps the iteration from overshooting where
the regret is flat (:func:`newton_solve`). The returned point is checked to be a strict local minimum.

The regret is measured against the plan the iteration tracks (tau_s), a local optimum of J: started from
a poor local optimum it can be zero at a wrong goal, which is why starting points come from the planner's
multi-start solves or from a previous estimate.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import casadi as ca
import numpy as np
import scipy.linalg

from comanip.estimation.buffered_function import BufferedFunction
from comanip.objectives.reward import goal_covariance
from comanip.planning.reach_problem import ReachProblem


@dataclass
class RegretPoint:
    """An iterate: constrained torques tau_c (H·n,), multipliers lam (2n,), plan torques tau_s (H·n,), goal g (d,)."""

    tau_c: np.ndarray
    lam: np.ndarray
    tau_s: np.ndarray
    goal: np.ndarray


@dataclass
class NewtonResult:
    """Where :func:`newton_solve` stopped and why."""

    point: RegretPoint
    status: str
    """'solved', 'max_iterations', 'max_wall_time', 'not_a_minimum' or 'failed'."""
    message: str
    iterations: int
    residual: float
    """max |F| at the returned point (normalised gradient units; m, m/s or rad, rad/s for F2)."""
    regret: float
    """J(tau_c) - J(tau_s) at the returned point, normalised (without the regulariser)."""


class RegretSystem:
    """The functions Newton's method on F needs, built once per model (observation step: once per n_o)."""

    def __init__(self, problem: ReachProblem):
        self.problem = problem
        model = problem.model
        self.n, self.d, self.H = model.n, model.d, model.H
        tau = ca.vec(problem.tau)
        normaliser = -problem.best_objective
        J = problem.objective / normaliser
        hessian, gradient = ca.hessian(J, ca.vertcat(tau, problem.goal))
        self._derivatives = BufferedFunction("regret_derivatives", [tau, problem.goal, problem.s0, problem.width],
                                             [J, gradient, hessian])
        W = goal_covariance(problem.width, self.d, model.goal_covariance)
        self._normaliser = ca.Function("normaliser", [problem.width], [normaliser])
        self._prior_weight = ca.Function("prior_weight", [problem.width], [ca.inv(W) / normaliser])
        self._observed = {}

    def observed_mean(self, n_o: int) -> BufferedFunction:
        """``(tau, s0, lam) -> (mu_no (2n,), A = dmu_no/dtau (2n, H·n), d²(lam^T mu_no)/dtau² (H·n, H·n))``."""
        if n_o not in self._observed:
            p = self.problem
            tau = ca.vec(p.tau)
            lam = ca.SX.sym("lam", 2 * self.n)
            mu = p.means[n_o]
            curvature = ca.hessian(ca.dot(lam, mu), tau)[0]
            self._observed[n_o] = BufferedFunction(f"observed_mean_{n_o}", [tau, p.s0, lam], [mu, ca.jacobian(mu, tau), curvature])
        return self._observed[n_o]

    def prior_weight(self, width: float) -> np.ndarray:
        """P = W^-1 / |J_best| (d, d) for width w (m)."""
        return np.asarray(self._prior_weight(width))

    def normaliser(self, width: float) -> float:
        """|J_best(w)|: J divided by it is what the iteration works with (m^-d)."""
        return float(self._normaliser(width))

    def linearise(self, point: RegretPoint, start, observed, n_o: int, prior, width) -> "Linearisation":
        """F and its Jacobian blocks at an iterate; ``prior`` None drops the regulariser."""
        Hn = self.H * self.n
        # the buffers are reused by the next call: copy the first evaluation before the second
        J_c, grad_c, hess_c = (v.copy() for v in self._derivatives(point.tau_c, point.goal, start, width))
        J_s, grad_s, hess_s = (v.copy() for v in self._derivatives(point.tau_s, point.goal, start, width))
        mu, A, curvature = (v.copy() for v in self.observed_mean(n_o)(point.tau_c, start, point.lam))
        P = np.zeros((self.d, self.d)) if prior is None else self.prior_weight(width)
        pull = np.zeros(self.d) if prior is None else 2 * P @ (point.goal - prior)
        regulariser = 0.0 if prior is None else float((point.goal - prior) @ P @ (point.goal - prior))
        return Linearisation(
            J_c=float(J_c), J_s=float(J_s), regulariser=regulariser, grad_c=grad_c[:Hn], H_c=hess_c[:Hn, :Hn],
            F1=grad_c[:Hn] + A.T @ point.lam, F2=mu - observed, F3=grad_s[:Hn],
            F4=grad_c[Hn:] - grad_s[Hn:] + pull,
            K_c=np.block([[hess_c[:Hn, :Hn] + curvature, A.T], [A, np.zeros((2 * self.n, 2 * self.n))]]),
            H_s=hess_s[:Hn, :Hn], Hc_tau_g=hess_c[:Hn, Hn:], Hs_tau_g=hess_s[:Hn, Hn:],
            Hc_gg=hess_c[Hn:, Hn:], Hs_gg=hess_s[Hn:, Hn:], P=P, A=A)


@dataclass
class Linearisation:
    """F = (F1, F2, F3, F4) at an iterate and the blocks of its Jacobian (see the module docstring)."""

    J_c: float
    """Normalised J at tau_c and at tau_s, and the normalised regulariser at g."""
    J_s: float
    regulariser: float
    grad_c: np.ndarray
    """dJ/dtau at tau_c (H·n,) and d²J/dtau² there (H·n square), for the predicted regret."""
    H_c: np.ndarray
    F1: np.ndarray
    F2: np.ndarray
    F3: np.ndarray
    F4: np.ndarray
    K_c: np.ndarray
    """KKT matrix of the constrained plan [[d²L/dtau², A^T], [A, 0]] (H·n + 2n square)."""
    H_s: np.ndarray
    """Hessian of J in the plan's torques (H·n square)."""
    Hc_tau_g: np.ndarray
    Hs_tau_g: np.ndarray
    Hc_gg: np.ndarray
    Hs_gg: np.ndarray
    P: np.ndarray
    A: np.ndarray

    @property
    def residual(self) -> float:
        return float(max(np.abs(F).max() for F in (self.F1, self.F2, self.F3, self.F4)))

    @cached_property
    def _solves(self) -> tuple[np.ndarray, np.ndarray]:
        """K_c^-1 [[Hc_tau_g, F1], [0, F2]] and H_s^-1 [Hs_tau_g, F3]: the torques' sensitivity to the goal
        (first d columns) and their Newton step at a fixed goal (last column)."""
        d = self.Hc_gg.shape[0]
        Xc = np.linalg.solve(self.K_c, np.column_stack([np.vstack([self.Hc_tau_g, np.zeros((len(self.F2), d))]),
                                                        np.r_[self.F1, self.F2]]))
        Xs = np.linalg.solve(self.H_s, np.column_stack([self.Hs_tau_g, self.F3]))
        return Xc, Xs

    @property
    def predicted_regret(self) -> float:
        """R(g) (normalised) predicted from this iterate: J at the inner problems' Newton steps for the same
        goal, from their quadratic models. Unlike Jc - J(tau_s) at the iterate itself it does not rise when
        the inner problems are solved more accurately, so it can judge a step while they are not yet."""
        Xc, Xs = self._solves
        d, Hn = self.Hc_gg.shape[0], len(self.F1)
        step_c, step_s = -Xc[:Hn, d], -Xs[:, d]
        J_c = self.J_c + self.grad_c @ step_c + 0.5 * step_c @ self.H_c @ step_c
        J_s = self.J_s + self.F3 @ step_s + 0.5 * step_s @ self.H_s @ step_s
        return float(J_c - J_s) + self.regulariser

    def step(self, goal_step_limit: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Newton step (d tau_c, d lam, d tau_s, d g) by block elimination.

        The goal step solves |d²R/dg²| d g = -r (eigenvalues mirrored, so it descends where the regret is
        not convex) and is at most goal_step_limit (m) long; the torque steps follow it exactly.
        """
        Hn = len(self.F1)
        Xc, Xs = self._solves
        d = self.Hc_gg.shape[0]
        reduced = self.reduced_hessian(Xc, Xs)
        rhs = self.F4 - self.Hc_tau_g.T @ Xc[:Hn, d] + self.Hs_tau_g.T @ Xs[:, d]
        eigenvalues, vectors = np.linalg.eigh(reduced)
        mirrored = np.maximum(np.abs(eigenvalues), 1e-10 * max(1.0, np.abs(eigenvalues).max()))
        d_goal = -vectors @ ((vectors.T @ rhs) / mirrored)
        length = np.linalg.norm(d_goal)
        if length > goal_step_limit:
            d_goal *= goal_step_limit / length
        d_c = -(Xc[:, d] + Xc[:, :d] @ d_goal)
        d_s = -(Xs[:, d] + Xs[:, :d] @ d_goal)
        return d_c[:Hn], d_c[Hn:], d_s, d_goal

    def reduced_hessian(self, Xc=None, Xs=None) -> np.ndarray:
        """d²R/dg² (d, d): the regret's Hessian in the goal with the inner problems kept optimal."""
        Hn = len(self.F1)
        d = self.Hc_gg.shape[0]
        if Xc is None:
            Xc = np.linalg.solve(self.K_c, np.vstack([self.Hc_tau_g, np.zeros((len(self.F2), d))]))
            Xs = np.linalg.solve(self.H_s, self.Hs_tau_g)
        reduced = (self.Hc_gg - self.Hc_tau_g.T @ Xc[:Hn, :d]) - (self.Hs_gg - self.Hs_tau_g.T @ Xs[:, :d]) + 2 * self.P
        return 0.5 * (reduced + reduced.T)

    def is_strict_minimum(self) -> tuple[bool, str]:
        """Second-order check: the plan, the constrained plan and the regret all have positive curvature."""
        Hn = len(self.F1)
        if not _positive_definite(self.H_s):
            return False, "the plan to the estimated goal is not a minimum of J"
        Z = scipy.linalg.null_space(self.A)
        if not _positive_definite(Z.T @ self.K_c[:Hn, :Hn] @ Z):
            return False, "the trajectory through the observation is not a minimum of J"
        if not _positive_definite(self.reduced_hessian()):
            return False, "the regret has no minimum at the estimated goal (a saddle or a flat direction)"
        return True, ""


def _positive_definite(matrix: np.ndarray) -> bool:
    try:
        np.linalg.cholesky(0.5 * (matrix + matrix.T))
        return True
    except np.linalg.LinAlgError:
        return False


def newton_solve(system: RegretSystem, point: RegretPoint, start, observed, n_o: int, prior, width: float, *,
                 observed_position: np.ndarray, tolerance: float, max_iterations: int, step_fraction: float,
                 expired) -> NewtonResult:
    """Newton's method on F from ``point`` until max |F| ≤ tolerance, then the second-order check.

    Globalised by a trust region on the goal step, judged by the regret itself: a trial point is kept when
    its predicted regret (:attr:`Linearisation.predicted_regret`) is lower, or, once the regret's changes
    are down at rounding level, when it halves the residual max |F| (Newton's quadratic endgame). Otherwise
    the goal step is shortened, the inner problems take a Newton step at the current goal (so the next
    comparison is made with them solved more accurately), and the step is retried. Far from the answer the
    regret is not convex, and early in a slow reach it is flat along the reach, where full steps overshoot.
    The radius starts at, and never exceeds, step_fraction·max(|g - x_o|, w), x_o = ``observed_position``
    (the observed end effector, m). ``expired()`` is asked before every step (wall-time budget).
    ``max_iterations`` bounds the number of linearisations (two Hessians of J each), which the result
    reports as iterations. Never raises: when the iteration does not converge, the last accepted iterate
    is returned with a status.
    """
    linearisation = system.linearise(point, start, observed, n_o, prior, width)
    radius = step_fraction * max(np.linalg.norm(point.goal - observed_position), width)
    status, message = "max_iterations", f"no convergence in {max_iterations} Newton iterations"
    count = 0

    def moved(by) -> tuple[RegretPoint, Linearisation]:
        nonlocal count
        count += 1
        d_tau_c, d_lam, d_tau_s, d_goal = by
        moved_point = RegretPoint(point.tau_c + d_tau_c, point.lam + d_lam, point.tau_s + d_tau_s, point.goal + d_goal)
        return moved_point, system.linearise(moved_point, start, observed, n_o, prior, width)

    while True:
        residual = linearisation.residual
        if not np.isfinite(residual):
            return NewtonResult(point, "failed", "J is not finite at the starting point", count, residual, np.nan)
        try:
            if residual <= tolerance:
                is_minimum, why = linearisation.is_strict_minimum()
                status, message = ("solved", "converged") if is_minimum else ("not_a_minimum", why)
                return NewtonResult(point, status, message, count, residual, linearisation.J_c - linearisation.J_s)
            if count >= max_iterations:
                break
            if expired():
                status, message = "max_wall_time", "the wall-time budget ran out"
                break
            ceiling = step_fraction * max(np.linalg.norm(point.goal - observed_position), width)
            step = linearisation.step(min(radius, ceiling))
            trial, trial_linearisation = moved(step)
            if _acceptable(linearisation, trial_linearisation):
                point, linearisation = trial, trial_linearisation
                radius = min(2 * radius, ceiling) if np.linalg.norm(step[3]) >= 0.99 * min(radius, ceiling) else radius
                continue
            radius = 0.25 * np.linalg.norm(step[3])
            if radius < _SHORTEST_GOAL_STEP * max(width, 1e-3):
                status, message = "failed", "the Newton iteration stalled (no goal step lowers the regret)"
                break
            inner, inner_linearisation = moved(linearisation.step(0.0))
        except np.linalg.LinAlgError:
            status, message = "failed", "a Newton system was singular (the observation does not pin the torques down)"
            break
        if np.isfinite(inner_linearisation.residual):
            point, linearisation = inner, inner_linearisation
    return NewtonResult(point, status, message, count, linearisation.residual, linearisation.J_c - linearisation.J_s)


def _acceptable(current: Linearisation, trial: Linearisation) -> bool:
    if not np.isfinite(trial.residual):
        return False
    before, after = current.predicted_regret, trial.predicted_regret
    if not np.isfinite(after):
        return False
    return after < before or (trial.residual < 0.5 * current.residual and after < before + _ROUNDING * (1 + abs(before)))


#: A goal step shorter than this fraction of the goal width means the iteration has stalled.
_SHORTEST_GOAL_STEP = 1e-7
#: Relative change of the (normalised) regret below which it no longer tells steps apart.
_ROUNDING = 1e-10
