"""One regularised factorisation: the Cholesky factor of a symmetric matrix shifted towards the identity
until it is positive definite, with the shift schedule a policy of the caller."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable, Iterator

import numpy as np
from scipy.linalg.lapack import dpotrf as _potrf, dpotri as _potri, dpotrs as _potrs


@dataclass(frozen=True)
class CholeskyFactor:
    """The Cholesky factor of a symmetric positive definite matrix M (N, N), as LAPACK's potrf leaves it."""

    triangle: np.ndarray
    """(N, N): R with Rᵀ R = M in its upper triangle, or L with L Lᵀ = M in its lower one (``lower``); the other
    triangle holds whatever the factored matrix held there."""
    lower: bool = False
    shift: float = 0.0
    """The relative shift delta the matrix was factored with (:func:`shifted_cholesky`)."""

    def solve(self, b: np.ndarray) -> np.ndarray:
        """M⁻¹ b for b (N,) or (N, k)."""
        x, info = _potrs(self.triangle, b, lower=self.lower)
        if info != 0:
            raise ValueError(f"LAPACK potrs rejected argument {-info} (factor {self.triangle.shape}, right-hand side {np.shape(b)})")
        return x

    def inverse(self) -> np.ndarray:
        """M⁻¹ (N, N), symmetric."""
        inverse, info = _potri(self.triangle, lower=self.lower)
        if info != 0:
            raise np.linalg.LinAlgError(f"LAPACK potri failed (info {info}, factor {self.triangle.shape})")
        triangle = np.tril if self.lower else np.triu
        return triangle(inverse) + triangle(inverse, -1 if self.lower else 1).T


def shifted_cholesky(matrix: np.ndarray, shifts: Iterable[float], lower: bool = False) -> CholeskyFactor | None:
    """The Cholesky factor of matrix + delta·s·I for the first relative shift delta in ``shifts`` that gives a
    positive definite matrix, s = max |diag matrix| (so delta is relative); None if none does.

    ``matrix`` (N, N) is read as symmetric (its upper triangle, or its lower one when ``lower``); delta = 0 factors
    it as it is. A matrix with a NaN or inf never gives a factor: it fails the factorisation or reaches the factor's
    diagonal, which is checked. A row-major (C-ordered) matrix is factored as its transpose, the same numbers in
    LAPACK's column-major order, so no reordering copy is made; the factor then sits in the other triangle
    (:attr:`CholeskyFactor.lower` says which).
    """
    shifted, diagonal, scale = None, None, None
    for delta in shifts:
        if delta == 0.0:
            candidate = matrix
        else:
            if shifted is None:
                diagonal = np.diag(matrix)
                scale = max(float(np.max(np.abs(diagonal))), np.finfo(float).tiny)
                shifted = matrix.copy()
            np.fill_diagonal(shifted, diagonal + delta * scale)
            candidate = shifted
        # LAPACK directly: scipy.linalg.cho_factor's checks and wrappers cost as much as factoring a 60 x 60 matrix
        transposed = candidate.flags.c_contiguous and not candidate.flags.f_contiguous
        factored_lower = lower != transposed
        factor, info = _potrf(candidate.T if transposed else candidate, lower=factored_lower, clean=False, overwrite_a=False)
        if info == 0 and math.isfinite(np.trace(factor)):
            return CholeskyFactor(factor, factored_lower, delta)
        if info < 0:
            raise ValueError(f"LAPACK potrf rejected argument {-info} (matrix {matrix.shape})")
    return None


def growing_shifts(last: float, least: float = 0.0) -> Iterator[float]:
    """IPOPT's schedule (Wächter & Biegler 2006, sec. 3.1): 0 first (unless ``least`` > 0), then the last
    successful shift / 3 (1e-4 if none was needed before), growing 8-fold (100-fold the first time), below
    1e20; never below ``least``."""
    if least == 0.0:
        yield 0.0
    delta = max(least, 1e-4 if last == 0 else max(last / 3, 1e-20))
    growth = 100.0 if last == 0 else 8.0
    while delta < 1e20:
        yield delta
        delta *= growth


def decade_shifts(first: float = 1e-8, largest: float = 1e6) -> Iterator[float]:
    """0, then ``first``, 10·first, ... up to the first shift beyond ``largest`` (a memoryless schedule)."""
    yield 0.0
    delta = first
    while True:
        yield delta
        if delta > largest:
            return
        delta *= 10
