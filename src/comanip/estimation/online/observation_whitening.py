"""Whitening of observation residuals under a plan's open-loop belief: the likelihood of many observations at once.

Observations y_k = C s(t_k) + v_k (C picks [q; qdot] from the state, v_k ~ N(0, R) independent) of a reach
that follows a plan open loop: the state's error e_i = s_i - mu_i about the plan's mean is a linear
Gauss–Markov process, e_0 = 0, e_{i+1} = A e_i + w_i, whose covariance is the plan's Sigma_i (so the noise
accumulated from step i to j is Sigma_j - A^(j-i) Sigma_i A^(j-i)^T). Between grid steps the state is
interpolated linearly (as the mean is): at t = (i + f) h the error is ((1 - f) I + f A) e_i + f w_i.
Observations in [t_i, t_{i+1}) are averaged into one residual per step, which sees O_i e_i,
O_i = C((1 - f̄) I + f̄ A) for their mean fraction f̄, with noise R / m_i + f̄² C Q_i C^T (Q_i the covariance
of w_i, which the later states carry too: their covariance with it is added).

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

    def __init__(self, cov: np.ndarray, powers: np.ndarray, m: int, steps=(), noise=(), fractions=()):
        self.cov, self.powers, self.m = cov, powers, m
        size = len(cov) * m
        self._factor = np.zeros((size, size))           # L
        self._inverse = np.zeros((size, size))          # L^-1
        self.steps: list[int] = [int(i) for i in steps]
        """Observed steps so far."""
        self._fractions = [float(f) for f in (fractions if len(fractions) else np.zeros(len(self.steps)))]
        self._observers = [self.observer(f) for f in self._fractions]
        if self.steps:
            S = len(self.steps)
            observers = np.array(self._observers)
            joint = self._cross(np.asarray(self.steps), observers, np.asarray(self.steps), observers, np.array(self._fractions))
            joint = joint.transpose(0, 2, 1, 3).reshape(S * m, S * m)
            joint = np.tril(joint) + np.tril(joint, -1).T
            joint += scipy.linalg.block_diag(*noise)
            L, info = lapack.dpotrf(joint, lower=1)
            if info != 0:
                raise np.linalg.LinAlgError("the observations' joint covariance is not positive definite")
            self._factor[:S * m, :S * m] = L
            self._inverse[:S * m, :S * m] = lapack.dtrtri(L, lower=1)[0]

    def observer(self, fraction: float) -> np.ndarray:
        """O (m, nx): what an observation a ``fraction`` f of a step after its step i sees of e_i,
        the first m entries of ((1 - f) I + f A) e_i (the rest of e(t), f w_i, is noise)."""
        A = self.powers[1]
        return ((1.0 - fraction) * np.eye(len(A)) + fraction * A)[:self.m]

    def _cross(self, rows: np.ndarray, row_observers: np.ndarray, columns: np.ndarray, column_observers: np.ndarray,
               column_fractions: np.ndarray) -> np.ndarray:
        """Blocks (R, K, m, m) of the covariance of observations at steps i in ``rows`` with those at k in
        ``columns`` (zero where i < k): O_i A^(i - k) Sigma_k O_k^T, plus, for i > k, the motor noise f_k w_k
        that the observation at k sees and step i carries: O_i A^(i - k - 1) Q_k (f_k C)^T."""
        m, H = self.m, len(self.cov) - 1
        lag = rows[:, None] - columns[None, :]
        blocks = (row_observers[:, None] @ self.powers[np.maximum(lag, 0)]) @ (self.cov[columns] @ column_observers.transpose(0, 2, 1))[None]
        A = self.powers[1]
        following = np.minimum(columns + 1, H)
        Q = self.cov[following] - A @ self.cov[columns] @ A.T                      # (K, nx, nx), zero at the last step
        shared = (row_observers[:, None] @ self.powers[np.maximum(lag - 1, 0)]) @ (Q[:, :, :m] * column_fractions[:, None, None])[None]
        blocks += np.where((lag >= 1)[:, :, None, None], shared, 0.0)
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

    def append(self, step: int, noise: np.ndarray, fraction: float = 0.0) -> None:
        """Add the averaged observation at ``step`` (after the last), on average ``fraction`` of a step after
        it, with noise covariance ``noise`` (m, m)."""
        m, S = self.m, len(self.steps)
        top = S * m
        O = self.observer(fraction)
        diagonal = O @ self.cov[step] @ O.T + noise
        if S:
            cross = self._cross(np.array([step]), O[None], np.asarray(self.steps), np.array(self._observers),
                                np.array(self._fractions))[0]                                             # (S, m, m)
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
        self._observers.append(O)
        self._fractions.append(float(fraction))

    def redo_last(self, noise: np.ndarray, fraction: float = 0.0) -> None:
        """The last step again, with a new noise covariance and fraction (more observations averaged into it)."""
        self._observers.pop()
        self._fractions.pop()
        self.append(self.steps.pop(), noise, fraction)

    def apply(self, columns: np.ndarray) -> np.ndarray:
        """Whitened columns (S, m, k) from residual columns (S, m, k) (each column one stacked residual)."""
        S, m, k = columns.shape
        return (self.matrix @ columns.reshape(S * m, k)).reshape(S, m, k)

    def transpose_apply(self, vector: np.ndarray) -> np.ndarray:
        """(L^-1)^T v (S, m) for a whitened vector v (S·m,)."""
        return (self.matrix.T @ vector).reshape(len(self.steps), self.m)
