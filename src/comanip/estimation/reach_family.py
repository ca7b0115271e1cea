"""The plans from rest of a rotation-invariant point mass, as one family of 1-D reaches: plan to any goal cheaply.

For a point mass with isotropic inertia and damping (M = m I, D = c I), isotropic or rank-one motor noise and
an isotropic goal covariance W, starting at rest at x_0, the model has no preferred direction and no
preferred origin: the plan to a goal g = x_0 + D u (|u| = 1) is the plan to x_0 + D e_1 turned onto u. Each
block of the state (q, qdot, and the activation stages, each (n,)) has a mean u · a_b,i(D) and a covariance
Q Sigma_i(D) Q^T, Q an orthogonal map with Q e_1 = u; the torque is u · tau_i(D). So the plans to the goals
along one axis, at distances D_1 < ... < D_K (m, geometric), give the plan to any goal: the member at
|g - x_0| (a cubic spline in log D between members), turned onto u. The spline's error against a real plan
is measured by tests/test_online_estimation.py (about 1e-5 m in the mean on the Cartesian preset).

The derivative of the mean with respect to the goal, which the online estimator needs for its Gauss–Newton
steps, follows from the same form: d(u a)/dg = a'(D) u u^T + (a(D) / D) (I - u u^T).

Whether a model is rotation-invariant is checked, not assumed: :class:`ReachFamily` plans one oblique reach
and compares it with the turned member (``invariance_error``); a model that fails (per-channel noise,
anisotropic mass) raises ValueError.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from comanip.planning.plan import Plan
from comanip.planning.planner import Planner

#: Largest difference (m, m/s, ...) between an oblique plan and the turned member for the model to count as
#: rotation-invariant: well above the planner's convergence noise, far below any model asymmetry.
INVARIANCE_TOLERANCE = 1e-5


@dataclass
class ReachPrediction:
    """The plan from rest at x_0 to one goal, read from the family. Shapes: H steps, nx state entries, n = d."""

    mean: np.ndarray
    """Mean state mu_i (H+1, nx)."""
    cov: np.ndarray
    """State covariance Sigma_i (H+1, nx, nx)."""
    torque: np.ndarray
    """Command tau_i (H, n)."""
    objective: float
    """J of the plan (SPEC §4 units)."""
    mean_jacobian: np.ndarray
    """d mu_i / d g (H+1, nx, d): how the mean moves with the goal (m per m, ...)."""


def householder(u: np.ndarray) -> np.ndarray:
    """Orthogonal (d, d) Q with Q e_1 = u for a unit vector u (d,): the reflection across the bisector of e_1 and u."""
    v = -u.copy()
    v[0] += 1.0
    norm2 = float(v @ v)
    if norm2 < 1e-24:
        return np.eye(u.size)
    return np.eye(u.size) - 2.0 * np.outer(v, v) / norm2


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
            and where it differs by more, it joins the family (``refinements`` rounds at most).

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
        of the members checked last: the tolerance of every prediction within the range."""
        self.invariance_error = self._invariance_error(planner)
        """Largest |mean| difference between an oblique plan and the turned member (state units)."""
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
        """The spline in log D through ``plans`` (sorted by distance)."""
        self.plans = plans
        self.distances = np.array([p.goal[0] for p in plans])
        """Member distances D_k (K,), m."""
        K, H, nb, n = len(plans), self.H, self.blocks, self.n
        along = np.array([p.mean.reshape(H + 1, nb, n)[:, :, 0] for p in plans])     # (K, H+1, blocks)
        torque = np.array([p.torque[:, 0] for p in plans])                          # (K, H)
        cov = np.array([p.cov for p in plans])                                      # (K, H+1, nx, nx)
        objective = np.array([p.objective for p in plans])
        self._sizes = [along[0].size, torque[0].size, cov[0].size, 1]
        stacked = np.column_stack([along.reshape(K, -1), torque.reshape(K, -1), cov.reshape(K, -1), objective])
        self._spline = CubicSpline(np.log(self.distances), stacked, axis=0)
        self._derivative = self._spline.derivative()

    def _refine(self, tolerance: float, rounds: int) -> float:
        """Check the spline at the midpoints of the intervals not yet known to be fine; add the plans that
        differ by more than ``tolerance`` (m); return the largest difference found in the last round."""
        d = self.model.d
        unchecked = set(range(len(self.plans) - 1))
        worst = np.inf
        for _ in range(rounds):
            added, worst = [], 0.0
            for k in sorted(unchecked):
                D = float(np.sqrt(self.distances[k] * self.distances[k + 1]))
                plan = self._plan(D, self.plans[k])
                if plan is None:
                    continue
                error = float(np.abs(self.prediction(np.zeros(d), plan.goal, derivative=False).mean[:, :d] - plan.mean[:, :d]).max())
                worst = max(worst, error)
                if error > tolerance:
                    added.append(plan)
            if not added:
                break
            plans = sorted(self.plans + added, key=lambda p: p.goal[0])
            self._fit(plans)
            new = {float(p.goal[0]) for p in added}
            unchecked = {k for k in range(len(plans) - 1) if float(plans[k].goal[0]) in new or float(plans[k + 1].goal[0]) in new}
        return worst

    def _invariance_error(self, planner: Planner) -> float:
        if self.model.d == 1:
            return 0.0
        k = len(self.plans) // 2
        u = np.ones(self.model.d) / np.sqrt(self.model.d)
        plan = planner.solve(np.zeros(self.nx), self.distances[k] * u, self.width)
        turned = self.prediction(np.zeros(self.model.d), self.distances[k] * u, derivative=False)
        return float(np.abs(plan.mean - turned.mean).max())

    def _unpack(self, values: np.ndarray):
        H, nb, nx = self.H, self.blocks, self.nx
        a, b, c = np.cumsum(self._sizes[:3])
        return values[:a].reshape(H + 1, nb), values[a:b], values[b:c].reshape(H + 1, nx, nx), float(values[c])

    def prediction(self, start_position: np.ndarray, goal: np.ndarray, *, derivative: bool = True) -> ReachPrediction:
        """The plan from rest at ``start_position`` (d,) m to ``goal`` (d,) m; ``derivative`` False leaves
        ``mean_jacobian`` zero (cheaper). The distance is clipped to the family's range."""
        d, n, nb = self.model.d, self.n, self.blocks
        offset = np.asarray(goal, dtype=float) - start_position
        D_raw = float(np.linalg.norm(offset))
        u = offset / D_raw if D_raw > 0 else np.eye(d)[0]
        D = float(np.clip(D_raw, self.distances[0], self.distances[-1]))
        along, torque, cov_frame, objective = self._unpack(self._spline(np.log(D)))
        Q = householder(u)
        mean = (along[:, :, None] * u).reshape(self.H + 1, nb * n)
        mean[:, :n] += start_position
        T = np.kron(np.eye(nb), Q)
        cov = T @ cov_frame @ T.T
        jacobian = np.zeros((self.H + 1, nb * n, d))
        if derivative:
            slope = self._derivative(np.log(D))[:self._sizes[0]].reshape(self.H + 1, nb) / D   # da/dD
            radial = np.outer(u, u)
            if D_raw < self.distances[0] or D_raw > self.distances[-1]:
                slope = np.zeros_like(slope)   # clipped: the mean does not move along u
            across = (np.eye(d) - radial) / max(D_raw, 1e-12)
            jacobian = (slope[:, :, None, None] * radial + along[:, :, None, None] * across).reshape(self.H + 1, nb * n, d)
        return ReachPrediction(mean=mean, cov=cov, torque=np.outer(torque, u), objective=objective, mean_jacobian=jacobian)
