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

from comanip.objectives.reward import goal_covariance
from comanip.planning.compiled import BufferedFunction
from comanip.planning.curvature import ReachCurvature
from comanip.planning.planner import Planner


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
    """The derivatives Newton's method on F needs, from the planner's own Newton terms (built once per model).

    J and its derivatives in tau come from the planner's structured Hessian (:mod:`comanip.planning.curvature`,
    exact for point masses; :mod:`comanip.planning.linearised_curvature`, approximate, for the Panda), and
    those in the goal from the same per-step pieces (``goal_derivatives``). The observed mean mu_no and
    A = dmu_no/dtau are exact. For a point mass mu_no is linear in tau, so A is constant and the
    constraint adds no curvature to the Lagrangian; for the Panda that curvature, d²(lam^T mu_no)/dtau², is
    left out (lam is small: the observation is a state the plan nearly passes through), which like the
    approximate Hessian only slows the iteration down: F itself is exact, so its root is unchanged.
    """

    def __init__(self, planner: Planner):
        problem = self.problem = planner.problem
        model = problem.model
        self.n, self.d, self.H = model.n, model.d, model.H
        self.linear = model.body.is_linear
        self.curvature = planner.curvature if planner.curvature is not None else ReachCurvature(problem)
        self._goal_covariance_form = model.goal_covariance
        self._observed: dict[int, tuple[BufferedFunction, np.ndarray]] = {}

    def derivatives(self, tau: np.ndarray, goal: np.ndarray, start: np.ndarray, width: float) -> "Derivatives":
        """Normalised J and its first and second derivatives in (tau, g) at torques tau (H·n,) and goal g (d,)."""
        curvature = self.curvature
        f, grad, data = curvature.evaluate(np.asarray(tau, dtype=float), np.r_[start, goal, width])
        grad_g, cross, hess_gg = curvature.goal_derivatives(data)
        return Derivatives(f, grad, grad_g, curvature.hessian(data), cross, hess_gg, data)

    def observed_mean(self, n_o: int, tau: np.ndarray, start: np.ndarray, data) -> tuple[np.ndarray, np.ndarray]:
        """(mu_no (2n,), A = dmu_no/dtau (2n, H·n)) at torques tau; ``data`` from the same evaluation."""
        if not self.linear:
            A = self.curvature.mean_sensitivities(data)[n_o].reshape(2 * self.n, -1)
            return self.curvature.trajectory(data)[0][n_o], A
        if n_o not in self._observed:
            p = self.problem
            tau_symbol = ca.vec(p.tau)
            mean = ca.Function(f"observed_mean_{n_o}", [tau_symbol, p.s0], [p.means[n_o]])
            # a linear body's mean is affine in tau: its Jacobian is a constant matrix
            self._observed[n_o] = (BufferedFunction(mean), np.asarray(ca.evalf(ca.jacobian(p.means[n_o], tau_symbol))))
        mean, A = self._observed[n_o]
        return mean(tau, start)[0].ravel(), A

    def prior_weight(self, width: float) -> np.ndarray:
        """P = W^-1 / |J_best| (d, d) for width w (m)."""
        return np.linalg.inv(goal_covariance(width, self.d, self._goal_covariance_form)) / self.normaliser(width)

    def normaliser(self, width: float) -> float:
        """|J_best(w)|: J divided by it is what the iteration works with (m^-d)."""
        return self.curvature.normaliser(width)

    def linearise(self, point: RegretPoint, start, observed, n_o: int, prior, width) -> "Linearisation":
        """F and its Jacobian blocks at an iterate; ``prior`` None drops the regulariser."""
        c = self.derivatives(point.tau_c, point.goal, start, width)
        s = self.derivatives(point.tau_s, point.goal, start, width)
        mu, A = self.observed_mean(n_o, point.tau_c, start, c.data)
        P = np.zeros((self.d, self.d)) if prior is None else self.prior_weight(width)
        pull = np.zeros(self.d) if prior is None else 2 * P @ (point.goal - prior)
        regulariser = 0.0 if prior is None else float((point.goal - prior) @ P @ (point.goal - prior))
        return Linearisation(
            J_c=c.f, J_s=s.f, regulariser=regulariser, grad_c=c.grad, H_c=c.hess,
            F1=c.grad + A.T @ point.lam, F2=mu - observed, F3=s.grad, F4=c.grad_g - s.grad_g + pull,
            H_s=s.hess, Hc_tau_g=c.cross, Hs_tau_g=s.cross, Hc_gg=c.hess_gg, Hs_gg=s.hess_gg, P=P, A=A)


@dataclass
class Derivatives:
    """Normalised J at one (tau, g) and its derivatives."""

    f: float
    grad: np.ndarray
    """dJ/dtau (H·n,)."""
    grad_g: np.ndarray
    """dJ/dg (d,)."""
    hess: np.ndarray
    """d²J/dtau² (H·n, H·n)."""
    cross: np.ndarray
    """d²J/dtau dg (H·n, d)."""
    hess_gg: np.ndarray
    """d²J/dg² (d, d)."""
    data: tuple
    """What the curvature object's ``evaluate`` returned (for further terms of the same point)."""


@dataclass
class Linearisation:
    """F = (F1, F2, F3, F4) at an iterate and the blocks of its Jacobian (see the module docstring)."""

    J_c: float
    """Normalised J at tau_c and at tau_s, and the normalised regulariser at g."""
    J_s: float
    regulariser: float
    grad_c: np.ndarray
    """dJ/dtau at tau_c (H·n,) and d²J/dtau² there (H·n square), which is also the Hessian of the constrained
    plan's Lagrangian (the observation constraint's curvature is zero or left out, see RegretSystem)."""
    H_c: np.ndarray
    F1: np.ndarray
    F2: np.ndarray
    F3: np.ndarray
    F4: np.ndarray
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
    def _cholesky(self) -> tuple[tuple | None, tuple | None]:
        """Cholesky factors of H_c and H_s, None where one is not positive definite."""
        return _cholesky_or_none(self.H_c), _cholesky_or_none(self.H_s)

    @cached_property
    def _solves(self) -> tuple[np.ndarray, np.ndarray]:
        """K_c^-1 [[Hc_tau_g, F1], [0, F2]] and H_s^-1 [Hs_tau_g, F3], K_c = [[H_c, A^T], [A, 0]] the
        constrained plan's KKT matrix: the torques' sensitivity to the goal (first d columns; multipliers in
        Xc's last 2n rows) and their Newton step at a fixed goal (last column).

        Raises LinAlgError when a system is singular."""
        d = self.Hc_gg.shape[0]
        factor_c, factor_s = self._cholesky
        right_c = np.column_stack([self.Hc_tau_g, self.F1])
        right_obs = np.column_stack([np.zeros((len(self.F2), d)), self.F2])
        if factor_c is not None:
            # block elimination on H_c's factor: A x = r2 with H_c x + A^T y = r1 gives (A H_c^-1 A^T) y = A H_c^-1 r1 - r2
            solved = scipy.linalg.cho_solve(factor_c, np.column_stack([right_c, self.A.T]), check_finite=False)
            x_right, x_At = solved[:, :d + 1], solved[:, d + 1:]
            y = np.linalg.solve(self.A @ x_At, self.A @ x_right - right_obs)
            Xc = np.vstack([x_right - x_At @ y, y])
        else:
            n2 = len(self.F2)
            K_c = np.block([[self.H_c, self.A.T], [self.A, np.zeros((n2, n2))]])
            Xc = np.linalg.solve(K_c, np.vstack([right_c, right_obs]))
        right_s = np.column_stack([self.Hs_tau_g, self.F3])
        Xs = (scipy.linalg.cho_solve(factor_s, right_s, check_finite=False) if factor_s is not None
              else np.linalg.solve(self.H_s, right_s))
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
        reduced = self.reduced_hessian()
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

    def reduced_hessian(self) -> np.ndarray:
        """d²R/dg² (d, d): the regret's Hessian in the goal with the inner problems kept optimal."""
        Hn = len(self.F1)
        d = self.Hc_gg.shape[0]
        Xc, Xs = self._solves
        reduced = (self.Hc_gg - self.Hc_tau_g.T @ Xc[:Hn, :d]) - (self.Hs_gg - self.Hs_tau_g.T @ Xs[:, :d]) + 2 * self.P
        return 0.5 * (reduced + reduced.T)

    def is_strict_minimum(self) -> tuple[bool, str]:
        """Second-order check: the plan, the constrained plan and the regret all have positive curvature."""
        factor_c, factor_s = self._cholesky
        if factor_s is None:
            return False, "the plan to the estimated goal is not a minimum of J"
        if factor_c is None:  # positive definite on the constraint's null space is enough
            Z = scipy.linalg.null_space(self.A)
            if _cholesky_or_none(Z.T @ self.H_c @ Z) is None:
                return False, "the trajectory through the observation is not a minimum of J"
        if _cholesky_or_none(self.reduced_hessian()) is None:
            return False, "the regret has no minimum at the estimated goal (a saddle or a flat direction)"
        return True, ""


def _cholesky_or_none(matrix: np.ndarray):
    """scipy's Cholesky factor of the symmetric part of ``matrix``, or None if it is not positive definite."""
    try:
        return scipy.linalg.cho_factor(0.5 * (matrix + matrix.T), check_finite=False)
    except np.linalg.LinAlgError:
        return None


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
