"""Constraints c(x) ≤ 0 for an active-set method: the iterate with its constraint values, the bounds and the
caller's constraints as one set of rows, the Newton step under the working set's linearisation, and the
restoration step onto violated constraints (:mod:`comanip.optim.active_set_newton` says how they are used)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
from scipy.linalg import lstsq

NO_ROWS, NO_MULTIPLIERS = np.zeros(0, dtype=int), np.zeros(0)
"""An empty working set and its multipliers (read only)."""


def least_norm(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """The least-norm least-squares solution of matrix (m, m) · y = rhs (m,): the working rows can depend on one
    another (a joint's position limit at one step and its velocity limits at the steps around it), and then the
    least-norm multipliers are the ones wanted. By LAPACK's complete orthogonal factorisation (gelsy: QR with
    column pivoting), which rank-reveals as the SVD does at a fraction of its cost; directions below m·eps of the
    largest count as zero, as in ``numpy.linalg.lstsq``."""
    return lstsq(matrix, rhs, cond=np.finfo(float).eps * len(rhs), lapack_driver="gelsy", check_finite=False)[0]


@dataclass(slots=True)
class Iterate:
    """A point x (N,) and what was evaluated there: f, its gradient (None after a value-only trial), the
    evaluation's data, the constraints c (bounds first) and rows(indices) of their Jacobian."""

    x: np.ndarray
    f: float
    g: np.ndarray | None
    data: Any
    c: np.ndarray
    rows: Callable[[np.ndarray], np.ndarray]
    largest: float = field(init=False)
    """max c (-inf without constraints): the working set, the violation and the merit's penalty read it first."""
    steepest: float = field(init=False)
    """max |g| (NaN where g holds a NaN, inf where it holds an inf; NaN without a gradient): the convergence test
    and :attr:`finite` read it."""

    def __post_init__(self):
        self.largest = float(self.c.max()) if len(self.c) else -math.inf
        self.steepest = float(np.abs(self.g).max()) if self.g is not None else math.nan

    @property
    def violation(self) -> float:
        """max(0, c): the largest violation, bounds included."""
        return max(0.0, self.largest)

    @property
    def finite(self) -> bool:
        """f finite, and every entry of g if it was evaluated."""
        return math.isfinite(self.f) and (self.g is None or math.isfinite(self.steepest))


class ConstraintSet:
    """c(x) ≤ 0 and rows of its Jacobian on demand: the finite bounds lb ≤ x ≤ ub (rows of ±I), then the
    caller's ``constraints`` ((x, data) -> (c (m,), rows(indices)), or None)."""

    def __init__(self, lb: np.ndarray, ub: np.ndarray, constraints):
        self.constraints = constraints
        finite_upper, finite_lower = np.isfinite(ub), np.isfinite(lb)
        self.unbounded = not (finite_upper.any() or finite_lower.any())
        # no bound (the point masses' torques): no index arrays to look up
        self.upper = NO_ROWS if self.unbounded else np.flatnonzero(finite_upper)
        self.lower = NO_ROWS if self.unbounded else np.flatnonzero(finite_lower)
        self.lb, self.ub, self.size = lb, ub, len(lb)
        self.all_finite = len(self.upper) == len(self.lower) == self.size

    def __call__(self, x, data):
        """(c (bounds then the caller's), rows(indices) -> their Jacobian rows (len(indices), N)) at x."""
        if self.unbounded:  # no finite bound (the point masses' torques): no rows at all
            bounds = NO_MULTIPLIERS
        elif self.all_finite:  # the usual bounded case (torque bounds): no index arrays to gather through
            bounds = np.concatenate([x - self.ub, self.lb - x])
        else:
            bounds = np.concatenate([x[self.upper] - self.ub[self.upper], self.lb[self.lower] - x[self.lower]])
        if self.constraints is None:
            return bounds, self._bound_rows
        c_user, user_rows = self.constraints(x, data)
        n_bounds = len(bounds)

        def rows(indices):
            out = np.zeros((len(indices), self.size))
            is_bound = indices < n_bounds
            out[is_bound] = self._bound_rows(indices[is_bound])
            if not is_bound.all():
                out[~is_bound] = user_rows(indices[~is_bound] - n_bounds)
            return out

        return np.concatenate([bounds, c_user]), rows

    def _bound_rows(self, indices):
        out = np.zeros((len(indices), self.size))
        n_upper = len(self.upper)
        upper = indices < n_upper
        out[np.flatnonzero(upper), self.upper[indices[upper]]] = 1.0
        out[np.flatnonzero(~upper), self.lower[indices[~upper] - n_upper]] = -1.0
        return out


def constrained_step(solve, g, c, A, margin: float, tolerance: float):
    """Newton step under the working set's linearised constraints; solve(b) applies the inverse of the regularised
    hessian to b (N,) or (N, k).

    A(indices) gives the constraints' Jacobian rows. Working rows: c_j > -margin; a row with a negative
    multiplier is dropped and the step recomputed unless it is violated by more than ``tolerance`` (then
    the step must restore it), or it is past its limit already and the step without it would move it further
    (then it is kept). (Keeping a row met to within the tolerance but just past its limit holds the
    iterate on the limit while the objective pulls it off: the step vanishes and the solve stalls with a large
    Lagrangian gradient.) Returns (step, multipliers, working rows, correct, optimality): correct(c_W) the
    least-H-norm move d with A_W d = -c_W, optimality max |g + A_Wᵀ multipliers| (the Lagrangian's gradient at the
    point, with the step's multipliers).
    """
    Hg = solve(g)
    near = np.flatnonzero(c > -margin)
    if not len(near):
        return -Hg, NO_MULTIPLIERS, NO_ROWS, None, float(np.abs(g).max())
    # every candidate row's H⁻¹ aᵀ once: a working set is a subset of them, and dropping or pinning a row only
    # selects other columns of these, so the loop below solves nothing more
    near_rows = A(near)
    near_HA = solve(near_rows.T)
    near_schur = near_rows @ near_HA
    near_rhs = c[near] - near_rows @ Hg
    working, pinned = np.ones(len(near), dtype=bool), np.zeros(len(near), dtype=bool)
    while True:
        kept = np.flatnonzero(working)
        if len(kept):
            multipliers = least_norm(near_schur[np.ix_(kept, kept)], near_rhs[kept])
            dropping = (multipliers < 0) & (c[near[kept]] <= tolerance) & ~pinned[kept]
            if dropping.any():
                working[kept[dropping]] = False
                continue
            multipliers = np.maximum(multipliers, 0.0)
            step = -(Hg + near_HA[:, kept] @ multipliers)
        else:
            multipliers, step = NO_MULTIPLIERS, -Hg
        # rows dropped together can push one another out: a dropped row already past its limit (within the
        # tolerance) that the step would drive further out returns to the working set for good (otherwise such
        # rows make the merit rise at first order along every step, and the solve fails short of convergence)
        if working.all():
            break
        dropped = np.flatnonzero(~working & (c[near] > 0))
        blocking = dropped[near_rows[dropped] @ step > 0]
        if not len(blocking):
            break
        pinned[blocking] = working[blocking] = True
    if not len(kept):
        return step, multipliers, NO_ROWS, None, float(np.abs(g).max())
    HA, schur = near_HA[:, kept], near_schur[np.ix_(kept, kept)]

    def correct(c_working, HA=HA, schur=schur):
        return -HA @ least_norm(schur, c_working)

    return step, multipliers, near[kept], correct, float(np.abs(g + near_rows[kept].T @ multipliers).max())


def restoration_step(point: Iterate) -> np.ndarray:
    """The least-norm move d with A_V d = -c_V onto the linearisation of the violated rows V at ``point``."""
    violated = np.flatnonzero(point.c > 0)
    rows = point.rows(violated)
    return -rows.T @ least_norm(rows @ rows.T, point.c[violated])
