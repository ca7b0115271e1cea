"""Whitening of observation residuals under a plan's open-loop belief: the likelihood of many observations at once.

Observations y_k = C s(t_k) + v_k (C picks [q; qdot] from the state, v_k ~ N(0, R) independent) of a reach
that follows a plan open loop: the state's error e_i = s_i - mu_i about the plan's mean is a linear
Gauss–Markov process, e_0 = 0, e_{i+1} = A e_i + w_i, whose covariance is the plan's Sigma_i (so the noise
accumulated from step i to j is Sigma_j - A^(j-i) Sigma_i A^(j-i)^T). Observations made within one step
see the same e_i (an observation between grid steps is read at the nearest step for its error, the mean is
interpolated), so they are averaged: one residual per observed step with noise R / m_i for m_i observations.

The inverse Cholesky factor of their joint covariance turns the correlated residuals r (S, 2n) into
independent standard normal values L^-1 r (a Kalman filter's normalised innovations; the prediction-error
decomposition of the joint Gaussian likelihood): -log p(r) = ½ |L^-1 r|² + ½ log det(C_joint) + const.
:class:`ObservationWhitening` factors once for a belief and then whitens any stack of columns (residuals
and their derivatives) with one matrix product.
Exact for point masses (linear dynamics, Gaussian states under open-loop torques), activation stages included.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg
from scipy.linalg import lapack


class ObservationWhitening:
    """L^-1 for averaged observations at increasing steps under the belief covariances ``cov``, C_joint = L L^T
    the joint covariance of the averaged residuals: built for all observed steps at once, then extended one
    step at a time (a new step is appended, the last one redone when more observations join it).

    Block (j, k), j ≥ k, of C_joint is C A^(i_j - i_k) Sigma_{i_k} C^T, plus the noise on the diagonal; L is
    its (block) Cholesky factor, so L^-1 r are the Kalman filter's normalised innovations.

    Args:
        cov: Sigma_i (H+1, nx, nx) of the plan.
        powers: A^k (H+1, nx, nx) for k = 0..H, A the (constant) state transition.
        m: observed entries (the first m of the state).
        steps: observed steps (S,), increasing; noise: their noise covariances (S, m, m).
    """

    def __init__(self, cov: np.ndarray, powers: np.ndarray, m: int, steps=(), noise=()):
        self.cov, self.powers, self.m = cov, powers, m
        size = len(cov) * m
        self._factor = np.zeros((size, size))           # L
        self._inverse = np.zeros((size, size))          # L^-1
        self.steps: list[int] = [int(i) for i in steps]
        """Observed steps so far."""
        if self.steps:
            S = len(self.steps)
            joint = self._cross(np.asarray(self.steps), np.asarray(self.steps)).transpose(0, 2, 1, 3).reshape(S * m, S * m)
            joint = np.tril(joint) + np.tril(joint, -1).T
            joint += scipy.linalg.block_diag(*noise)
            L, info = lapack.dpotrf(joint, lower=1)
            if info != 0:
                raise np.linalg.LinAlgError("the observations' joint covariance is not positive definite")
            self._factor[:S * m, :S * m] = L
            self._inverse[:S * m, :S * m] = lapack.dtrtri(L, lower=1)[0]

    def _cross(self, rows: np.ndarray, columns: np.ndarray) -> np.ndarray:
        """Blocks C A^(i - k) Sigma_k C^T (R, K, m, m) for steps i in ``rows``, k in ``columns`` (zero where i < k)."""
        m = self.m
        lag = rows[:, None] - columns[None, :]
        blocks = self.powers[np.maximum(lag, 0)][:, :, :m, :] @ self.cov[columns][None, :, :, :m]
        blocks[lag < 0] = 0.0
        return blocks

    @property
    def matrix(self) -> np.ndarray:
        """L^-1 (S·m, S·m), lower block-triangular (a view)."""
        size = len(self.steps) * self.m
        return self._inverse[:size, :size]

    @property
    def log_det(self) -> float:
        """log det of the joint covariance of the averaged observations."""
        size = len(self.steps) * self.m
        return 2.0 * float(np.log(np.diag(self._factor)[:size]).sum())

    def append(self, step: int, noise: np.ndarray) -> None:
        """Add the averaged observation at ``step`` (after the last) with noise covariance ``noise`` (m, m)."""
        m, S = self.m, len(self.steps)
        top = S * m
        diagonal = self.cov[step][:m, :m] + noise
        if S:
            cross = self._cross(np.array([step]), np.asarray(self.steps))[0]       # (S, m, m): block (new, k)
            y = self._inverse[:top, :top] @ cross.transpose(0, 2, 1).reshape(top, m)     # L^-1 c
            diagonal = diagonal - y.T @ y
        L, info = lapack.dpotrf(0.5 * (diagonal + diagonal.T), lower=1)
        if info != 0:
            raise np.linalg.LinAlgError("the innovation covariance is not positive definite")
        L_inv = lapack.dtrtri(L, lower=1)[0]
        self._factor[top:top + m, top:top + m] = L
        self._inverse[top:top + m, top:top + m] = L_inv
        if S:
            self._factor[top:top + m, :top] = y.T
            self._inverse[top:top + m, :top] = -L_inv @ (y.T @ self._inverse[:top, :top])
        self.steps.append(int(step))

    def redo_last(self, noise: np.ndarray) -> None:
        """The last step again, with a new noise covariance (more observations averaged into it)."""
        self.append(self.steps.pop(), noise)

    def apply(self, columns: np.ndarray) -> np.ndarray:
        """Whitened columns (S, m, k) from residual columns (S, m, k) (each column one stacked residual)."""
        S, m, k = columns.shape
        return (self.matrix @ columns.reshape(S * m, k)).reshape(S, m, k)

    def transpose_apply(self, vector: np.ndarray) -> np.ndarray:
        """(L^-1)^T v (S, m) for a whitened vector v (S·m,)."""
        return (self.matrix.T @ vector).reshape(len(self.steps), self.m)
