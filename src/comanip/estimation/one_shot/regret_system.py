"""The regret's first-order conditions F and their Jacobian at an iterate (see :mod:`comanip.estimation.one_shot.regret_newton`).

Notation (``docs/notation.md``): torques tau (H·n,), goal g (d,), J normalised by |J_best(w)|; the constrained plan tau_c with
multipliers lam of the observation constraint (rows ``observed_rows`` of mu_no(tau_c) = s_o) and nu_c of
the path limits it holds as equalities (``active_c``); the plan tau_s with multipliers nu_s of its active
limits (``active_s``). Path limits are those of :mod:`comanip.planning.path_limits` (joint positions and
velocities of an arm; a point mass has none). With A_c = d[observed rows; active limits]/dtau and A_s the
rows of tau_s's active limits:

    F1 = grad_tau J(tau_c, g) + A_c^T [lam; nu_c]           (H·n)
    F2 = [mu_no(tau_c) - s_o]_observed_rows ; c(tau_c)_active_c
    F3 = grad_tau J(tau_s, g) + A_s^T nu_s                    (H·n)
    F5 = c(tau_s)_active_s
    F4 = grad_g J(tau_c, g) - grad_g J(tau_s, g) + 2 P (g - g_bar)   (d)

The limits do not depend on g, so the envelope theorem gives F4 with or without them.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import casadi as ca
import numpy as np
import scipy.linalg

from comanip.estimation.goal_prior import GoalPrior
from comanip.optim import CholeskyFactor, decade_shifts, shifted_cholesky
from comanip.caching.buffered_function import BufferedFunction
from comanip.planning.curvature import ReachCurvature
from comanip.planning.path_limits import PathLimits
from comanip.planning.planner import Planner
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.terms import ReachTerms

_NO_INDICES = np.zeros(0, dtype=int)


@dataclass
class RegretPoint:
    """An iterate (or a step between iterates, same fields): constrained torques tau_c (H·n,) with multipliers
    lam (observed rows) and nu_c (its active limits), plan torques tau_s (H·n,) with multipliers nu_s, goal g (d,).

    ``active_c`` and ``active_s`` index the path-limit constraints (:meth:`PathLimits.constraints`, flattened)
    held as equalities; a step carries its point's.
    """

    tau_c: np.ndarray
    lam: np.ndarray
    tau_s: np.ndarray
    goal: np.ndarray
    nu_c: np.ndarray = field(default_factory=lambda: np.zeros(0))
    nu_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    active_c: np.ndarray = field(default_factory=lambda: _NO_INDICES)
    active_s: np.ndarray = field(default_factory=lambda: _NO_INDICES)

    def plus(self, step: "RegretPoint", scale: float = 1.0) -> "RegretPoint":
        """This point moved by ``scale`` times ``step`` (same active sets)."""
        return replace(self, tau_c=self.tau_c + scale * step.tau_c, lam=self.lam + scale * step.lam,
                       tau_s=self.tau_s + scale * step.tau_s, goal=self.goal + scale * step.goal,
                       nu_c=self.nu_c + scale * step.nu_c, nu_s=self.nu_s + scale * step.nu_s)


@dataclass
class Derivatives:
    """Normalised J at one (tau, g) and its derivatives."""

    f: float
    grad: np.ndarray
    """dJ/dtau (H·n,)."""
    grad_g: np.ndarray
    """dJ/dg (d,)."""
    hess: np.ndarray
    """d²J/dtau² (H·n, H·n), exact for point masses, approximate for arms."""
    cross: np.ndarray
    """d²J/dtau dg (H·n, d)."""
    hess_gg: np.ndarray
    """d²J/dg² (d, d)."""
    data: ReachTerms
    """What the curvature's ``evaluate`` returned (for further terms of the same point)."""


@dataclass(frozen=True)
class ObservedMean:
    """The plan's mean state at the observed step, mu_no (2n,), and its Jacobian A = dmu_no/dtau (2n, H·n)."""

    mean: np.ndarray
    jacobian: np.ndarray


@dataclass(frozen=True)
class LimitRows:
    """The path limits at torques tau: c (all of them, flattened; ≤ 0 where they hold) and the rows dc/dtau of the
    active ones (len(active), H·n)."""

    values: np.ndarray
    rows: np.ndarray


class RegretSystem:
    """The derivatives Newton's method on F needs, from the planner's own Newton terms (built once per model).

    J and its derivatives in tau come from the planner's structured Hessian (:mod:`comanip.planning.curvature`,
    exact for point masses; :mod:`comanip.planning.linearised_curvature`, approximate, for the Panda), and
    those in the goal from the same per-step pieces (``goal_derivatives``). The observed mean mu_no, the
    limits and their Jacobians are exact. For a point mass mu_no is linear in tau, so A is constant and the
    constraints add no curvature to the Lagrangian; for an arm that curvature, d²([lam; nu]^T c)/dtau², is
    left out, which like the approximate Hessian only slows the iteration down: F itself is exact, so its
    root is unchanged.
    """

    def __init__(self, planner: Planner):
        problem = self.problem = planner.problem
        model = problem.model
        self.n, self.d, self.H = model.n, model.d, model.H
        self.linear = model.body.is_linear
        self.curvature = planner.curvature if planner.curvature is not None else ReachCurvature(problem)
        self.exact = self.linear and self.curvature.exact
        """True when F's Jacobian is exact (point masses)."""
        self.path_limits = PathLimits.of(model)
        self._limits = self.path_limits.for_newton(self.curvature) if self.path_limits.active else None
        self._observed: dict[int, tuple[BufferedFunction, np.ndarray]] = {}

    def derivatives(self, tau: np.ndarray, goal: np.ndarray, start: np.ndarray, width: float) -> Derivatives:
        """Normalised J and its first and second derivatives in (tau, g) at torques tau (H·n,) and goal g (d,)."""
        curvature = self.curvature
        evaluation = curvature.evaluate(np.asarray(tau, dtype=float), ReachParameters(start, goal, width))
        data = evaluation.data
        goal = curvature.goal_derivatives(data)
        return Derivatives(evaluation.f, evaluation.gradient, goal.gradient, curvature.hessian(data), goal.cross, goal.hessian, data)

    def observed_mean(self, n_o: int, tau: np.ndarray, start: np.ndarray, data) -> ObservedMean:
        """mu_no and its Jacobian at torques tau; ``data`` from the same evaluation."""
        if not self.linear:
            A = self.curvature.mean_sensitivities(data)[n_o].reshape(2 * self.n, -1)
            return ObservedMean(self.curvature.mean_path(data)[n_o], A)
        if n_o not in self._observed:
            p = self.problem
            tau_symbol = ca.vec(p.tau)
            mean = ca.Function(f"observed_mean_{n_o}", [tau_symbol, p.s0], [p.means[n_o]])
            # a linear body's mean is affine in tau: its Jacobian is a constant matrix
            self._observed[n_o] = (BufferedFunction(mean), np.asarray(ca.evalf(ca.jacobian(p.means[n_o], tau_symbol))))
        mean, A = self._observed[n_o]
        return ObservedMean(mean(tau, start)[0].ravel(), A)

    def limits(self, tau: np.ndarray, data, active: np.ndarray) -> LimitRows:
        """The path limits at torques tau, with the rows of the ``active`` ones."""
        if self._limits is None:
            return LimitRows(np.zeros(0), np.zeros((0, self.H * self.n)))
        c, rows = self._limits(tau, data)
        return LimitRows(c, rows(active) if len(active) else np.zeros((0, self.H * self.n)))

    def merits(self, point: RegretPoint, start, observed, n_o: int, observed_rows: np.ndarray, width: float,
               weights: tuple[float, float]) -> float:
        """l1 merit of the two plans at the point's goal: J(tau_c) + mu_c |c_c|_1 + J(tau_s) + mu_s |c_s|_1,
        (mu_c, mu_s) = ``weights``, c the constraints each holds (observed rows and active limits)."""
        total = 0.0
        params = ReachParameters(start, point.goal, width)
        for tau, active, mu, observe in ((point.tau_c, point.active_c, weights[0], True),
                                         (point.tau_s, point.active_s, weights[1], False)):
            evaluation = self.curvature.value_and_data(np.asarray(tau, dtype=float), params)
            data = evaluation.data
            violation = np.abs(self.limits(tau, data, _NO_INDICES).values[active]).sum()
            if observe:
                mean = self.observed_mean(n_o, tau, start, data).mean if self.linear else self.curvature.mean_path(data)[n_o]
                violation += np.abs((mean - observed)[observed_rows]).sum()
            total += evaluation.f + mu * violation
        return total

    def limits_at_step(self, step: int) -> np.ndarray:
        """Indices of the path limits on the mean state of ``step`` (1..H) in the flattened constraint vector."""
        per_side = self.H * 2 * self.n
        entries = (step - 1) * 2 * self.n + np.arange(2 * self.n)
        return np.r_[entries, per_side + entries]

    def prior_weight(self, prior: GoalPrior, width: float) -> np.ndarray:
        """P = P0^-1 / |J_best| (d, d) for the prior's covariance P0 (the paper's: W) and width w (m)."""
        return prior.precision / self.normaliser(width)

    def normaliser(self, width: float) -> float:
        """|J_best(w)|: J divided by it is what the iteration works with (m^-d)."""
        return self.curvature.normaliser(width)

    def linearise(self, point: RegretPoint, start, observed, n_o: int, observed_rows: np.ndarray, prior, width) -> "Linearisation":
        """F and its Jacobian blocks at an iterate; ``observed_rows`` are the entries of s_o the constrained
        plan must meet; ``prior`` (a :class:`GoalPrior`) None drops the regulariser."""
        c = self.derivatives(point.tau_c, point.goal, start, width)
        s = self.derivatives(point.tau_s, point.goal, start, width)
        observed_mean = self.observed_mean(n_o, point.tau_c, start, c.data)
        limits_c = self.limits(point.tau_c, c.data, point.active_c)
        limits_s = self.limits(point.tau_s, s.data, point.active_s)
        A_c = np.vstack([observed_mean.jacobian[observed_rows], limits_c.rows])
        P = np.zeros((self.d, self.d)) if prior is None else self.prior_weight(prior, width)
        pull = np.zeros(self.d) if prior is None else 2 * P @ (point.goal - prior.mean)
        regulariser = 0.0 if prior is None else float((point.goal - prior.mean) @ P @ (point.goal - prior.mean))
        return Linearisation(
            J_c=c.f, J_s=s.f, regulariser=regulariser, grad_c=c.grad, grad_s=s.grad, H_c=c.hess, H_s=s.hess,
            F1=c.grad + A_c.T @ np.r_[point.lam, point.nu_c],
            F2=np.r_[(observed_mean.mean - observed)[observed_rows], limits_c.values[point.active_c]],
            F3=s.grad + limits_s.rows.T @ point.nu_s, F5=limits_s.values[point.active_s],
            F4=c.grad_g - s.grad_g + pull, Hc_tau_g=c.cross, Hs_tau_g=s.cross, Hc_gg=c.hess_gg, Hs_gg=s.hess_gg,
            P=P, A_c=A_c, A_s=limits_s.rows, limits_c=limits_c.values, limits_s=limits_s.values, regularise=not self.exact)


@dataclass
class Linearisation:
    """F = (F1, .., F5) at an iterate and the blocks of its Jacobian (see the module docstring)."""

    J_c: float
    """Normalised J at tau_c and at tau_s, and the normalised regulariser at g."""
    J_s: float
    regulariser: float
    grad_c: np.ndarray
    """dJ/dtau at tau_c and at tau_s (H·n,), for the predicted regret."""
    grad_s: np.ndarray
    H_c: np.ndarray
    """d²J/dtau² at tau_c and at tau_s (H·n square): the Hessians of the two plans' Lagrangians, the
    constraints' curvature being zero (point masses) or left out (arms)."""
    H_s: np.ndarray
    F1: np.ndarray
    F2: np.ndarray
    F3: np.ndarray
    F5: np.ndarray
    F4: np.ndarray
    Hc_tau_g: np.ndarray
    Hs_tau_g: np.ndarray
    Hc_gg: np.ndarray
    Hs_gg: np.ndarray
    P: np.ndarray
    A_c: np.ndarray
    """Jacobian of the constrained plan's constraints (observed rows, then active limits) (rows, H·n)."""
    A_s: np.ndarray
    """Jacobian of the plan's active limits (rows, H·n)."""
    limits_c: np.ndarray
    """All path-limit values c(tau_c) and c(tau_s) (≤ 0 when they hold), for updating the active sets."""
    limits_s: np.ndarray
    regularise: bool = False
    """Shift an indefinite H_c or H_s by a multiple of I until it is positive definite before solving (for
    approximate Hessians, as the planner does); otherwise solve the KKT systems as they are (exact Newton)."""

    @property
    def residual(self) -> float:
        return float(max(np.abs(F).max(initial=0.0) for F in (self.F1, self.F2, self.F3, self.F4, self.F5)))

    @property
    def stationarity(self) -> float:
        """max |F1|, |F3|: the plans' stationarity."""
        return max(np.abs(self.F1).max(), np.abs(self.F3).max())

    @property
    def constraint_error(self) -> float:
        """max |F2|, |F5|: the plans' constraints."""
        return max(np.abs(self.F2).max(initial=0.0), np.abs(self.F5).max(initial=0.0))

    @cached_property
    def _factor_c(self) -> CholeskyFactor | None:
        """The Cholesky factor of H_c (shifted if ``regularise``), None where it is not positive definite."""
        return self._factored(self.H_c)

    @cached_property
    def _factor_s(self) -> CholeskyFactor | None:
        """The Cholesky factor of H_s, as :attr:`_factor_c`."""
        return self._factored(self.H_s)

    def _factored(self, H: np.ndarray) -> CholeskyFactor | None:
        return shifted_cholesky(_symmetric_part(H), decade_shifts() if self.regularise else (0.0,))

    @cached_property
    def _solves(self) -> tuple[np.ndarray, np.ndarray]:
        """K_c^-1 [[Hc_tau_g, F1], [0, F2]] and K_s^-1 [[Hs_tau_g, F3], [0, F5]], K = [[H, A^T], [A, 0]] the
        plans' KKT matrices: the torques' (and multipliers') sensitivity to the goal (first d columns) and
        their Newton step at a fixed goal (last column). Raises LinAlgError when a system is singular."""
        d = self.Hc_gg.shape[0]
        factor_c, factor_s = self._factor_c, self._factor_s
        Xc = _kkt_solve(self.H_c, factor_c, self.A_c, np.column_stack([self.Hc_tau_g, self.F1]),
                        np.column_stack([np.zeros((len(self.F2), d)), self.F2]))
        Xs = _kkt_solve(self.H_s, factor_s, self.A_s, np.column_stack([self.Hs_tau_g, self.F3]),
                        np.column_stack([np.zeros((len(self.F5), d)), self.F5]))
        return Xc, Xs

    @property
    def predicted_regret(self) -> float:
        """R(g) (normalised) predicted from this iterate: J at the inner problems' Newton steps for the same
        goal, from their quadratic models. Unlike Jc - J(tau_s) at the iterate itself it does not rise when
        the inner problems are solved more accurately, so it can judge a step while they are not yet."""
        Xc, Xs = self._solves
        d, Hn = self.Hc_gg.shape[0], len(self.F1)
        step_c, step_s = -Xc[:Hn, d], -Xs[:Hn, d]
        J_c = self.J_c + self.grad_c @ step_c + 0.5 * step_c @ self.H_c @ step_c
        J_s = self.J_s + self.grad_s @ step_s + 0.5 * step_s @ self.H_s @ step_s
        return float(J_c - J_s) + self.regulariser

    def step(self, goal_step_limit: float, point: RegretPoint) -> RegretPoint:
        """Newton step from ``point`` (same fields, its active sets) by block elimination.

        The goal step solves |d²R/dg²| d g = -r (eigenvalues mirrored, so it descends where the regret is
        not convex) and is at most goal_step_limit (m) long; the torque and multiplier steps follow it exactly.
        """
        Hn = len(self.F1)
        Xc, Xs = self._solves
        d = self.Hc_gg.shape[0]
        rhs = self.F4 - self.Hc_tau_g.T @ Xc[:Hn, d] + self.Hs_tau_g.T @ Xs[:Hn, d]
        eigenvalues, vectors = np.linalg.eigh(self.reduced_hessian())
        mirrored = np.maximum(np.abs(eigenvalues), 1e-10 * max(1.0, np.abs(eigenvalues).max()))
        d_goal = -vectors @ ((vectors.T @ rhs) / mirrored)
        length = np.linalg.norm(d_goal)
        if length > goal_step_limit:
            d_goal *= goal_step_limit / length
        d_c = -(Xc[:, d] + Xc[:, :d] @ d_goal)
        d_s = -(Xs[:, d] + Xs[:, :d] @ d_goal)
        n_lam = len(point.lam)
        return replace(point, tau_c=d_c[:Hn], lam=d_c[Hn:Hn + n_lam], nu_c=d_c[Hn + n_lam:],
                       tau_s=d_s[:Hn], nu_s=d_s[Hn:], goal=d_goal)

    def plan_goal_sensitivity(self) -> np.ndarray:
        """d tau_s / d g (H·n, d): how the plan to the goal (its active limits held) moves with the goal."""
        Xs = self._solves[1]
        return -Xs[:len(self.F3), :self.Hc_gg.shape[0]]

    def reduced_hessian(self) -> np.ndarray:
        """d²R/dg² (d, d): the regret's Hessian in the goal with the inner problems kept optimal."""
        Hn = len(self.F1)
        d = self.Hc_gg.shape[0]
        Xc, Xs = self._solves
        reduced = (self.Hc_gg - self.Hc_tau_g.T @ Xc[:Hn, :d]) - (self.Hs_gg - self.Hs_tau_g.T @ Xs[:Hn, :d]) + 2 * self.P
        return 0.5 * (reduced + reduced.T)

    def not_a_minimum(self, exact: bool = True) -> str | None:
        """Second-order check: None when the plan, the constrained plan and the regret all have positive curvature,
        else which does not, in words.

        With approximate Hessians (``exact`` False) only the regret's d×d curvature is checked: the plans'
        Hessians are then approximations that may be indefinite at a minimum (the planner does not check them).
        """
        factor_c, factor_s = self._factor_c, self._factor_s
        if exact and not _positive_on_null_space(self.H_s, factor_s, self.A_s):
            return "the plan to the estimated goal is not a minimum of J"
        if exact and not _positive_on_null_space(self.H_c, factor_c, self.A_c):
            return "the trajectory through the observation is not a minimum of J"
        if _cholesky_or_none(self.reduced_hessian()) is None:
            return "the regret has no minimum at the estimated goal (a saddle or a flat direction)"
        return None


def _kkt_solve(H: np.ndarray, factor: CholeskyFactor | None, A: np.ndarray, right: np.ndarray, right_constraints: np.ndarray) -> np.ndarray:
    """[[H, A^T], [A, 0]]^-1 [right; right_constraints], by block elimination on H's Cholesky factor
    (``factor``, None when H is not positive definite: then by LU of the whole matrix)."""
    m = A.shape[0]
    if factor is None:
        K = np.block([[H, A.T], [A, np.zeros((m, m))]])
        return np.linalg.solve(K, np.vstack([right, right_constraints]))
    k = right.shape[1]
    solved = factor.solve(np.column_stack([right, A.T]))
    if m == 0:
        return solved
    # H x + A^T y = r, A x = r_c  =>  (A H^-1 A^T) y = A H^-1 r - r_c,  x = H^-1 r - H^-1 A^T y
    x_right, x_At = solved[:, :k], solved[:, k:]
    y = np.linalg.solve(A @ x_At, A @ x_right - right_constraints)
    return np.vstack([x_right - x_At @ y, y])


def _positive_on_null_space(H: np.ndarray, factor: CholeskyFactor | None, A: np.ndarray) -> bool:
    """H positive definite on the null space of A (H itself positive definite is enough)."""
    if factor is not None:
        return True
    Z = scipy.linalg.null_space(A) if A.shape[0] else np.eye(H.shape[0])
    return _cholesky_or_none(Z.T @ H @ Z) is not None


def _cholesky_or_none(matrix: np.ndarray) -> CholeskyFactor | None:
    """The Cholesky factor of the symmetric part of ``matrix``, or None if it is not positive definite."""
    return shifted_cholesky(_symmetric_part(matrix), (0.0,))


def _symmetric_part(matrix: np.ndarray) -> np.ndarray:
    return 0.5 * (matrix + matrix.T)
