"""The plans from rest of a rotation-invariant point mass, as one family of 1-D reaches: plan to any goal cheaply.

For a point mass with isotropic inertia and damping (M = m I, D = c I), isotropic or rank-one motor noise and
an isotropic goal covariance W, starting at rest at x_0, the model has no preferred direction and no
preferred origin: the plan to a goal g = x_0 + D u (|u| = 1) is the plan to x_0 + D e_1 turned onto u. Each
block of the state (q, qdot, and the activation stages, each (n,)) has a mean u · a_b,i(D) and a covariance
Q Sigma_i(D) Q^T, Q an orthogonal map with Q e_1 = u; the torque is u · tau_i(D). So the plans to the goals
along one axis, at distances D_1 < ... < D_K (m, geometric), give the plan to any goal: the member at
|g - x_0| (a cubic spline in log D between members), turned onto u. The spline's error against a real plan
is checked at build time (``ReachFamily.interpolation_error``).

The derivative of the mean with respect to the goal, which the online estimator needs for its Gauss–Newton
steps, follows from the same form: d(u a)/dg = a'(D) u u^T + (a(D) / D) (I - u u^T).

Whether a model is rotation-invariant is checked, not assumed: :class:`ReachFamily` plans one oblique reach
and compares it with the turned member (``invariance_error``); a model that fails (per-channel noise,
anisotropic mass) raises ValueError.
"""

from __future__ import annotations

import bisect
import math
import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.interpolate import CubicSpline

from comanip.belief.propagation import linearised_step_function
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner
from comanip.planning.reflection import reflection_onto

INVARIANCE_TOLERANCE = 1e-4
"""Largest difference between an oblique plan and the turned member, in each state entry relative to its largest
magnitude along the plan (at least 1 of its unit: m, m/s, N), for the model to count as rotation-invariant: above
the planner's convergence noise (largest for narrow goals and large muscle forces), far below any model asymmetry
(per-channel noise differs by several hundredths)."""


@dataclass(frozen=True)
class FamilyMember:
    """The family's plan to one distance along e_1, before it is turned onto a goal's direction. Shapes: H steps,
    nx state entries."""

    distance: float
    """D (m), within the family's range."""
    along: np.ndarray
    """The mean along the axis per state block, a_b,i(D) (H+1, blocks)."""
    covariance: np.ndarray
    """Sigma_i(D) (H+1, nx, nx), in the member's frame."""


@dataclass
class ReachPrediction:
    """The plan from rest at x_0 to one goal, read from the family. Shapes: H steps, nx state entries, n = d."""

    mean: np.ndarray
    """Mean state mu_i (H+1, nx)."""
    cov: np.ndarray | None
    """State covariance Sigma_i (H+1, nx, nx); None when not asked for."""
    torque: np.ndarray
    """Command tau_i (H, n)."""
    objective: float
    """J of the plan (docs/formulation.md §4 units)."""
    mean_jacobian: np.ndarray | None = None
    """d mu_i / d g (H+1, nx, d): how the mean moves with the goal (m per m, ...); None when not asked for."""
    direction: np.ndarray | None = None
    """u (d,), the unit vector from the start to the goal."""
    curvature: np.ndarray | None = None
    """d²a/dD² (H+1, blocks) of the mean along u (per m); with ``mixed``, the second derivatives of the mean
    (order 2; :meth:`hessian_contraction`)."""
    mixed: np.ndarray | None = None
    """a'/D - a/D² (H+1, blocks) (per m)."""
    member: "FamilyMember | None" = None
    """The member it was turned from, when its covariance was asked for (the forecast reads it again)."""

    def hessian_contraction(self, z: np.ndarray) -> np.ndarray:
        """sum_ik z_ik d² mu_ik / d g² (d, d) for weights z (H+1, nx): with P = I - u u^T the second derivative
        of the entry u_c a_b is a'' u_c u u^T + (a'/D - a/D²)(P_c u^T + u P_c^T + u_c P), P_c P's row c."""
        u = self.direction
        d = u.size
        z = z.reshape(-1, d)                                 # (H+1 · blocks, d)
        radial = u[:, None] * u
        across = np.eye(d) - radial
        zeta = self.mixed.ravel() @ z
        pz = across @ zeta
        outer = pz[:, None] * u
        return float(self.curvature.ravel() @ (z @ u)) * radial + outer + outer.T + float(zeta @ u) * across


class ReachFamily:
    """Plans from rest to the goals x_0 + D_k e_1 for one model and width, and the plan to any goal from them.

    Args:
        planner: the model's planner (a point mass; activation stages allowed).
        width: goal width w (m).
        distances: (D_min, D_max), m, the range of goal distances covered; goals nearer or farther are read
            at the nearest end of the range.
        size: number of members to start from (geometrically spaced over the range).
        tolerance: largest acceptable difference (m) between the interpolated mean position and a real plan;
            the plan at the midpoint (in log D) of every pair of neighbouring members is solved and compared,
            and where it differs by more, it joins the family (``refinements`` rounds at most); the range ends
            below an interval that is still off (e.g. where plans of a short horizon have several optima).

    Raises ValueError when the model is not rotation-invariant (see the module docstring), or when the
    plan to D_min does not converge.
    """

    def __init__(self, planner: Planner, width: float, distances: tuple[float, float] = (0.005, 1.0), size: int = 32,
                 tolerance: float = 1e-4, refinements: int = 4):
        model = planner.model
        if not model.body.is_linear:
            raise ValueError(f"a reach family needs a point-mass body (linear dynamics), got {model.body.name!r}")
        t_begin = time.perf_counter()
        self.model, self.width = model, float(width)
        self.n, self.nx, self.H = model.n, model.state_size, model.H
        self.blocks = self.nx // self.n
        self._planner = planner
        plans: list[Plan] = []
        warm = None
        for D in np.geomspace(distances[0], distances[1], size):
            plan = self._plan(D, warm)
            if plan is None:
                if not plans:
                    raise ValueError(f"the plan to the nearest family distance {D:g} m did not converge")
                break
            plans.append(plan)
            warm = plan
        self._fit(plans)
        self.interpolation_error = self._refine(tolerance, refinements)
        """Largest |mean position| difference (m) between the spline and a real plan at the midpoints (in log D)
        of the intervals between members: the accuracy of every prediction within the range (at most the
        tolerance; the range ends where that cannot be reached)."""
        self.invariance_error = self._invariance_error(planner)
        """Largest |mean| difference between an oblique plan and the turned member, in each state entry relative to its
        largest magnitude along the plan (at least 1 of its unit)."""
        if self.invariance_error > INVARIANCE_TOLERANCE:
            raise ValueError(f"the model {model.name!r} is not rotation-invariant (an oblique plan differs from the turned "
                             f"axis plan by {self.invariance_error:.3g}): a reach family needs M = m I, D = c I, isotropic "
                             "or rank-one noise and an isotropic goal covariance")
        self.build_time = time.perf_counter() - t_begin
        """Wall time of building the family (s)."""

    def _plan(self, D: float, warm: Plan | None) -> Plan | None:
        """The plan from rest at 0 to D e_1, or None unless it succeeds (converges to finite values and reaches
        the goal within the horizon)."""
        model = self.model
        plan = self._planner.solve(np.zeros(self.nx), np.r_[D, np.zeros(model.d - 1)], self.width, warm_start=warm)
        return plan if plan.success and np.all(np.isfinite(plan.mean)) and np.all(np.isfinite(plan.cov)) else None

    def _fit(self, plans: list[Plan]) -> None:
        """The splines in log D through ``plans`` (sorted by distance): one for the mean, torque and J, one for
        the covariance (read only when asked for)."""
        self.plans = plans
        self.distances = np.array([p.goal[0] for p in plans])
        """Member distances D_k (K,), m."""
        K, H, nb, n = len(plans), self.H, self.blocks, self.n
        self.member_along = np.array([p.mean.reshape(H + 1, nb, n)[:, :, 0] for p in plans])
        """Each member's mean along its axis, per state block (K, H+1, blocks)."""
        self.member_cov = np.array([p.cov for p in plans])
        """Each member's state covariance in its own frame (K, H+1, nx, nx)."""
        torque = np.array([p.torque[:, 0] for p in plans])
        objective = np.array([p.objective for p in plans])
        log_D = np.log(self.distances)
        self._path = CubicSpline(log_D, np.column_stack([self.member_along.reshape(K, -1), torque, objective]), axis=0)
        self._cov = CubicSpline(log_D, self.member_cov.reshape(K, -1), axis=0)
        self._knots = log_D.tolist()
        self._low, self._high = float(self.distances[0]), float(self.distances[-1])
        self._eye = np.eye(self.model.d)

    def _refine(self, tolerance: float, rounds: int) -> float:
        """Check the spline at the midpoint (in log D) of every interval between members; where a real plan
        differs by more than ``tolerance`` (m), add it to the family and check the two halves in the next
        round. After ``rounds`` rounds, intervals still off (or whose midpoint plan does not succeed) end the
        family's range below them. Returns the largest difference (m) over the intervals kept."""
        d = self.model.d
        errors: dict[float, float] = {}                 # lower member's distance -> midpoint error of its interval
        unchecked = set(range(len(self.plans) - 1))
        for round_ in range(rounds + 1):
            added = []
            for k in sorted(unchecked):
                D = float(np.sqrt(self.distances[k] * self.distances[k + 1]))
                plan = self._plan(D, self.plans[k])
                if plan is None:
                    errors[float(self.distances[k])] = np.inf
                    continue
                predicted = self.prediction(np.zeros(d), plan.goal, order=0, covariance=False).mean[:, :d]
                errors[float(self.distances[k])] = error = float(np.abs(predicted - plan.mean[:, :d]).max())
                if error > tolerance and round_ < rounds:
                    added.append(plan)
            if not added:
                break
            plans = sorted(self.plans + added, key=lambda p: p.goal[0])
            self._fit(plans)
            new = {float(p.goal[0]) for p in added}
            unchecked = {k for k in range(len(plans) - 1) if float(plans[k].goal[0]) in new or float(plans[k + 1].goal[0]) in new}
        kept = len(self.plans)
        for k in range(len(self.plans) - 1):
            if errors.get(float(self.distances[k]), 0.0) > tolerance:
                kept = k + 1
                break
        if kept < len(self.plans):
            if kept < 4:
                raise ValueError(f"the reach family is not accurate to {tolerance:g} m even at short distances "
                                 f"(interval from {self.distances[0]:g} m); raise the tolerance or the size")
            self._fit(self.plans[:kept])
        return max((e for D, e in errors.items() if D < self.distances[-1]), default=0.0)

    def _invariance_error(self, planner: Planner) -> float:
        if self.model.d == 1:
            return 0.0
        k = len(self.plans) // 2
        u = np.ones(self.model.d) / np.sqrt(self.model.d)
        plan = planner.solve(np.zeros(self.nx), self.distances[k] * u, self.width)
        turned = self.prediction(np.zeros(self.model.d), self.distances[k] * u, order=0, covariance=False)
        scale = np.maximum(1.0, np.abs(plan.mean).max(axis=0))
        return float((np.abs(plan.mean - turned.mean) / scale).max())

    def along(self, distances: np.ndarray) -> np.ndarray:
        """The mean along the axis per state block, a_b,i(D) (M, H+1, blocks), at distances (M,) m within the range."""
        x = np.log(np.clip(distances, self._low, self._high))
        k = np.clip(np.searchsorted(self._path.x, x) - 1, 0, len(self._knots) - 2)
        dx = (x - self._path.x[k])[:, None]
        size = (self.H + 1) * self.blocks
        c = self._path.c[:, k, :size]
        return (((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]).reshape(len(distances), self.H + 1, self.blocks)

    @cached_property
    def transition_powers(self) -> np.ndarray:
        """A^m (H+1, nx, nx), m = 0..H: the powers of the model's one-step state map (linear dynamics)."""
        A = np.asarray(linearised_step_function(self.model.body, self.model.h)(np.zeros(self.nx), np.zeros(self.n))[1])
        powers = np.empty((self.H + 1, self.nx, self.nx))
        powers[0] = np.eye(self.nx)
        for m in range(1, self.H + 1):
            powers[m] = A @ powers[m - 1]
        return powers

    def in_range(self, distance: float) -> float:
        """``distance`` (m) clipped to the family's range: where the family reads it."""
        return min(max(distance, self._low), self._high)

    def member(self, distance: float) -> FamilyMember:
        """The member at ``distance`` (m, read at the nearest end of the range outside it)."""
        D = self.in_range(distance)
        return FamilyMember(D, self.along(np.array([D]))[0], self.member_covariance(D))

    def member_covariance(self, distance: float) -> np.ndarray:
        """Sigma_i (H+1, nx, nx) of the plan to ``distance`` (m, within the range) along e_1, in that frame."""
        x = math.log(min(max(distance, self._low), self._high))
        k = min(max(bisect.bisect_left(self._knots, x) - 1, 0), len(self._knots) - 2)
        dx = x - self._knots[k]
        c = self._cov.c[:, k]
        return (((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]).reshape(self.H + 1, self.nx, self.nx)

    def frame(self, u: np.ndarray) -> np.ndarray:
        """T (nx, nx): the orthogonal map Q (Q e_1 = u) applied to every state block."""
        Q, n = reflection_onto(u), self.n
        T = np.zeros((self.nx, self.nx))
        for b in range(self.blocks):
            T[b * n:(b + 1) * n, b * n:(b + 1) * n] = Q
        return T

    def prediction(self, start_position: np.ndarray, goal: np.ndarray, *, order: int = 1, covariance: bool = True) -> ReachPrediction:
        """The plan from rest at ``start_position`` (d,) m to ``goal`` (d,) m, with derivatives of its mean in
        the goal up to ``order`` (0, 1 or 2) and its covariance when ``covariance`` (else ``cov`` is None).
        A distance outside the family's range is read at the nearest end (the mean then moves only across)."""
        d, n, nb, H = self.model.d, self.n, self.blocks, self.H
        offset = np.asarray(goal, dtype=float) - start_position
        D_raw = math.sqrt(float(offset @ offset))
        u = offset / D_raw if D_raw > 0 else self._eye[0]
        D = min(max(D_raw, self._low), self._high)
        inside = D == D_raw
        x = math.log(D)
        k = min(max(bisect.bisect_left(self._knots, x) - 1, 0), len(self._knots) - 2)
        dx = x - self._knots[k]
        c = self._path.c[:, k]
        values = ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]
        size = (H + 1) * nb
        along = values[:size].reshape(H + 1, nb)
        mean = (along[:, :, None] * u).reshape(H + 1, nb * n)
        mean[:, :n] += start_position
        cov = member = None
        if covariance:
            T = self.frame(u)
            member = FamilyMember(D, along, self.member_covariance(D))
            cov = T @ member.covariance @ T.T
        jacobian = curvature = mixed = None
        if order >= 1:
            radial = u[:, None] * u
            across = self._eye - radial
            first = ((3 * c[0] * dx + 2 * c[1]) * dx + c[2])[:size].reshape(H + 1, nb)      # da/dlog D
            slope = first / D if inside else np.zeros_like(first)                            # da/dD
            D_safe = max(D_raw, 1e-12)
            jacobian = (slope[:, :, None, None] * radial + (along / D_safe)[:, :, None, None] * across).reshape(H + 1, nb * n, d)
            if order >= 2:
                second = (6 * c[0] * dx + 2 * c[1])[:size].reshape(H + 1, nb)
                curvature = (second - first) / D**2 if inside else np.zeros_like(first)      # d²a/dD²
                mixed = slope / D_safe - along / D_safe**2
        return ReachPrediction(mean=mean, cov=cov, torque=values[size:size + H, None] * u, objective=float(values[-1]),
                               mean_jacobian=jacobian, direction=u, curvature=curvature, mixed=mixed, member=member)
