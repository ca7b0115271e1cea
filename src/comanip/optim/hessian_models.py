"""How the active-set Newton method (:mod:`comanip.optim.active_set_newton`) gets the regularised Hessian it
steps with: :class:`ExactHessian` assembles the caller's Hessian at every iteration and reuses its factor for
chord steps; :class:`SecantHessian` corrects an approximate Hessian with symmetric rank-one (SR1) updates,
drops them where they leave it indefinite, assembles it lazily and carries the updates into the last factor by
the Woodbury identity. Both regularise by IPOPT's growing shifts, more strongly after a failed line search, and
both can take their first Hessian and its factor made ahead of the solve (:class:`PreparedHessian`: a real-time
iteration's preparation)."""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Callable

import numpy as np

from comanip.optim.factorisation import CholeskyFactor, growing_shifts, shifted_cholesky
from comanip.optim.newton_loop import Stop
from comanip.optim.status import Status

RECOVERY_SHIFT = 1e-3
"""The least relative shift delta after the first failed line search (ten times more after each further one)."""
REUSE_RATIO = 0.1
"""An exact Hessian's factor is reused while each step cuts the gradient by at least this factor."""
CORRECTED_SHIFT_LIMIT = 0.1
"""The largest relative shift a secant-corrected Hessian is factored with: where it needs more, the corrections are
dropped and the assembled Hessian alone is factored, with the shifts it needs."""


@dataclass(frozen=True)
class PreparedHessian:
    """A Hessian (N, N) assembled and factored ahead of the solve whose first step uses it, at a point near that
    solve's start (:func:`prepare_hessian`)."""

    matrix: np.ndarray
    factor: CholeskyFactor
    """Its regularised factor, shifted as the schedule of a fresh solve shifts it."""


def prepare_hessian(matrix: np.ndarray) -> PreparedHessian | None:
    """``matrix`` (N, N) and its factor with the shifts a fresh solve would try; None where none gives a factor."""
    factor = shifted_cholesky(matrix, growing_shifts(0.0))
    return None if factor is None else PreparedHessian(matrix, factor)


class _Regularised:
    """The shifted Cholesky factorisation with IPOPT's shift schedule, remembering the last shift needed; the first
    matrix is the prepared one where there is one."""

    shift_last = 0.0

    def __init__(self, hessian: Callable, prepared: PreparedHessian | None):
        self.hessian, self.prepared = hessian, prepared

    def _assembled(self, point) -> np.ndarray:
        """The Hessian at ``point``: the prepared one until its factor has been used."""
        return self.hessian(point.data) if self.prepared is None else self.prepared.matrix

    def _factored(self, matrix: np.ndarray, recoveries: int, below: float = np.inf) -> CholeskyFactor | None:
        """The factor of matrix with the first shift of the schedule that makes it positive definite, among the
        shifts ``below`` this one; None if none does. The prepared matrix's factor is taken as it is, once."""
        prepared, self.prepared = self.prepared, None
        if prepared is not None and matrix is prepared.matrix and not recoveries and prepared.factor.shift < below:
            self.shift_last = prepared.factor.shift or self.shift_last
            return prepared.factor
        # after a failed line search, a stronger shift turns the step towards steepest descent
        least = RECOVERY_SHIFT * 10.0 ** (recoveries - 1) if recoveries else 0.0
        factor = shifted_cholesky(matrix, itertools.takewhile(lambda delta: delta < below,
                                                              growing_shifts(self.shift_last, least)))
        if factor is not None and factor.shift > 0:
            self.shift_last = factor.shift
        return factor


class ExactHessian(_Regularised):
    """An exact Hessian, assembled at every iteration. Chord steps: while no constraint is in the working set and
    the last step cut max |∇f| at least tenfold (``REUSE_RATIO``), the next step reuses that step's factor
    instead of a new Hessian (Kelley 2003, sec. 5.4)."""

    def __init__(self, hessian: Callable, prepared: PreparedHessian | None = None):
        super().__init__(hessian, prepared)
        self.kept = None
        """The factor of the last free step and the optimality where it was taken, for chord steps."""

    def chord_factor(self, optimality: float, recoveries: int) -> CholeskyFactor | None:
        """The kept factor when a chord step from a free point of this ``optimality`` may use it, else None."""
        if recoveries == 0 and self.kept is not None and optimality <= REUSE_RATIO * self.kept[1]:
            self.kept = (self.kept[0], optimality)
            return self.kept[0]
        return None

    def factor(self, point, recoveries: int, model_held: bool) -> UpdatedFactor | Stop:
        """The regularised Hessian at ``point``, factored (with no updates), or why there is none."""
        self.kept = None
        hessian = self._assembled(point)
        factor = self._factored(hessian, recoveries)
        if factor is None:
            return _not_factored(hessian)
        return UpdatedFactor(factor)

    def stepped(self, factor: CholeskyFactor, optimality: float, free: bool) -> None:
        """A step was computed with ``factor`` at a point of this ``optimality``; a free one may be reused."""
        if free:
            self.kept = (factor, optimality)

    def forget(self) -> None:
        """After a failed line search: no chord step from the factor that failed."""
        self.kept = None


class SecantHessian(_Regularised):
    """An approximate Hessian with secant corrections, assembled every ``refresh`` iterations (module docstring
    of :mod:`comanip.optim.active_set_newton`)."""

    def __init__(self, hessian: Callable, refresh: int, prepared: PreparedHessian | None = None):
        super().__init__(hessian, prepared)
        self.refresh = refresh
        self.correction = None
        self.previous = None
        """(x, g) before the last step."""
        self.assembled, self.age = None, 0
        """The last assembled hessian, and the iterations it has served."""
        self.updated: UpdatedFactor | None = None
        """The last factored matrix with the secant updates since."""

    def chord_factor(self, optimality: float, recoveries: int) -> None:
        """Never: the secant corrections change the matrix at every step."""
        return None

    def factor(self, point, recoveries: int, model_held: bool) -> UpdatedFactor | Stop:
        """The regularised, corrected Hessian at ``point`` as a factor with the secant updates since it was
        factored, or why there is none. ``model_held``: the last step was a full one with no constraint in the
        working set."""
        reused = self.assembled is not None and self.age < self.refresh and model_held
        if not reused:
            self.assembled, self.age = self._assembled(point), 0
        self.age += 1
        self.correction = np.zeros_like(self.assembled) if self.correction is None else self.correction
        update = None
        if self.previous is not None:
            update = symmetric_rank_one_update(self.correction, self.assembled, point.x - self.previous[0],
                                               point.g - self.previous[1])
        self.previous = (point.x, point.g)
        # between assemblies the last factor takes the secant updates (Woodbury), unless it was shifted or
        # an update leaves the matrix indefinite: then the matrix is factored anew, with the shifts
        reusable = reused and not recoveries and self.updated.cholesky.shift == 0
        self.updated = self.updated.updated(update) if reusable else None
        if self.updated is None:
            factor = self._corrected_factor(recoveries)
            if factor is None:
                return _not_factored(self.assembled)
            self.updated = UpdatedFactor(factor)
        return self.updated

    def _corrected_factor(self, recoveries: int) -> CholeskyFactor | None:
        """The factor of the assembled Hessian with the secant corrections, shifted by less than
        ``CORRECTED_SHIFT_LIMIT``; where that needs more, the corrections are dropped and the assembled Hessian alone
        is factored, with the shifts it needs.

        Such corrections learnt curvature from steps the model does not hold along: they can make the matrix
        strongly indefinite while the assembled Hessian is positive definite, and the shift that cures it, shrinking
        a third per iteration, would hold the steps short for many iterations. Smaller shifts stay: along joint limits the corrections supply curvature the assembled Hessian
        lacks, and without them the steps crawl."""
        if self.correction.any():
            factor = self._factored(self.assembled + self.correction, recoveries, below=CORRECTED_SHIFT_LIMIT)
            if factor is not None:
                return factor
            self.correction = np.zeros_like(self.assembled)
        return self._factored(self.assembled, recoveries)

    def stepped(self, factor, optimality: float, free: bool) -> None:
        """Nothing to remember: the corrections were updated in :meth:`factor`."""

    def forget(self) -> None:
        """After a failed line search: drop the corrections (they may have learnt curvature from far away) and
        assemble anew."""
        self.correction, self.previous, self.assembled = None, None, None


def _not_factored(hessian: np.ndarray) -> Stop:
    """The failure when no shift of the schedule gave a factor of ``hessian``, with why in words."""
    return Stop(Status.FAILED, "Hessian not finite" if not np.isfinite(hessian).all() else
                "no positive definite regularised Hessian")


@dataclass(frozen=True)
class RankOneUpdate:
    """A symmetric rank-one change sign·u uᵀ of a matrix."""

    u: np.ndarray
    """(N,)."""
    sign: float
    """±1."""


def symmetric_rank_one_update(correction: np.ndarray, H: np.ndarray, s: np.ndarray, y: np.ndarray) -> RankOneUpdate | None:
    """correction += r rᵀ / (rᵀ s), r = y - (H + correction) s, in place; skipped when rᵀ s is tiny
    (the usual safeguard: |rᵀ s| ≥ 1e-8 |r| |s|). correction and H (N, N), s and y (N,).

    Returns correction's change; None when skipped."""
    r = y - H @ s - correction @ s
    denominator = r @ s
    if abs(denominator) > 1e-8 * np.linalg.norm(r) * np.linalg.norm(s):
        u = r / np.sqrt(abs(denominator))  # u_i u_j = u_j u_i: the correction stays exactly symmetric
        sign = float(np.sign(denominator))
        correction += np.outer(u, sign * u)
        return RankOneUpdate(u, sign)
    return None


class UpdatedFactor:
    """Solves with a regularised hessian M = F + U S Uᵀ: F's Cholesky factor (from
    :func:`~comanip.optim.shifted_cholesky`), and the secant updates made since it was factored (none for an exact
    Hessian), U = [u_1 ... u_m] (N, m) with signs S = diag(±1), by the Woodbury identity
    M⁻¹ b = F⁻¹ b - F⁻¹U C⁻¹ Uᵀ F⁻¹ b, C = S⁻¹ + Uᵀ F⁻¹ U (m, m): two triangular solves per update instead of
    a factorisation."""

    def __init__(self, cholesky: CholeskyFactor, vectors: np.ndarray | None = None, signs: np.ndarray | None = None):
        self.cholesky = cholesky
        self.vectors = np.zeros((len(cholesky.triangle), 0)) if vectors is None else vectors
        self.signs = np.zeros(0) if signs is None else signs
        if len(self.signs):
            self._solved = cholesky.solve(self.vectors)  # F⁻¹ U
            self._capacitance = np.diag(self.signs) + self.vectors.T @ self._solved  # S⁻¹ = S for signs ±1

    @property
    def factor(self) -> CholeskyFactor | None:
        """M's Cholesky factor when no update was made since it was factored (M = F), else None."""
        return None if len(self.signs) else self.cholesky

    def solve(self, b: np.ndarray) -> np.ndarray:
        """M⁻¹ b for b (N,) or (N, k)."""
        x = self.cholesky.solve(b)
        if not len(self.signs):
            return x
        return x - self._solved @ np.linalg.solve(self._capacitance, self._solved.T @ b)

    def updated(self, update: RankOneUpdate | None) -> "UpdatedFactor | None":
        """The factor of M + sign·u uᵀ (``update``; None: M itself), or None when that matrix is not safely positive definite. By Haynsworth's inertia additivity
        M + U S Uᵀ is positive definite exactly when C has as many negative eigenvalues as S has negative signs;
        C nearly singular counts as not."""
        if update is None:
            return self
        factor = UpdatedFactor(self.cholesky, np.column_stack([self.vectors, update.u]), np.append(self.signs, update.sign))
        eigenvalues = np.linalg.eigvalsh(factor._capacitance)
        if np.sum(eigenvalues < 0) != np.sum(factor.signs < 0) or np.min(np.abs(eigenvalues)) <= 1e-8 * np.max(np.abs(eigenvalues)):
            return None
        return factor
