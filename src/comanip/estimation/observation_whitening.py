"""Whitening of observation residuals under a plan's open-loop belief: the likelihood of many observations at once.

Observations y_k = C s(t_k) + v_k (C picks [q; qdot] from the state, v_k ~ N(0, R) independent) of a reach
that follows a plan open loop: the state's error e_i = s_i - mu_i about the plan's mean is a linear
Gauss–Markov process, e_0 = 0, e_{i+1} = A e_i + w_i, whose covariance is the plan's Sigma_i (so the noise
accumulated from step i to j is Sigma_j - A^(j-i) Sigma_i A^(j-i)^T). Observations made within one step
see the same e_i (an observation between grid steps is read at the nearest step for its error, the mean is
interpolated), so they are averaged: one residual per observed step with noise R / m_i for m_i observations.

A Kalman filter over the observed steps turns the correlated residuals r (S, 2n) into independent standard
normal innovations L^-1 r (the prediction-error decomposition of the joint Gaussian likelihood):
-log p(r) = ½ |L^-1 r|² + ½ log det(C_joint) + const. :class:`ObservationWhitening` precomputes the gains once
for a belief and then whitens any stack of columns (residuals and their derivatives) with matrix products only.
Exact for point masses (linear dynamics, Gaussian states under open-loop torques), activation stages included.
"""

from __future__ import annotations

import numpy as np


class ObservationWhitening:
    """L^-1 for averaged observations at steps ``steps`` (S,) increasing, under belief covariances ``cov``.

    Args:
        cov: Sigma_i (H+1, nx, nx) of the plan.
        steps: observed steps (S,), strictly increasing.
        noise: covariance of each averaged observation (S, m, m) (R / m_i).
        powers: A^k (H+1, nx, nx) for k = 0..H, A the (constant) state transition.
        m: observed entries (the first m of the state).
    """

    def __init__(self, cov: np.ndarray, steps: np.ndarray, noise: np.ndarray, powers: np.ndarray, m: int):
        self.steps, self.m = steps, m
        self._transitions, self._inverse_factors, self._gains = [], [], []
        self.log_det = 0.0
        """log det of the joint covariance of the averaged observations."""
        previous, P = None, None
        for s, i in enumerate(steps):
            if previous is None:
                Phi = powers[i]
                P_pred = cov[i]
            else:
                Phi = powers[i - previous]
                P_pred = Phi @ P @ Phi.T + cov[i] - Phi @ cov[previous] @ Phi.T
            S = P_pred[:m, :m] + noise[s]
            L = np.linalg.cholesky(0.5 * (S + S.T))
            L_inv = np.linalg.inv(L)
            gain = P_pred[:, :m] @ L_inv.T @ L_inv
            P = P_pred - gain @ P_pred[:m, :]
            self.log_det += 2.0 * float(np.log(np.diag(L)).sum())
            self._transitions.append(Phi)
            self._inverse_factors.append(L_inv)
            self._gains.append(gain)
            previous = i

    def apply(self, columns: np.ndarray) -> np.ndarray:
        """Whitened columns (S, m, k) from residual columns (S, m, k) (each column one stacked residual)."""
        k = columns.shape[2]
        out = np.empty_like(columns)
        x = np.zeros((self._transitions[0].shape[0], k))
        for s, (Phi, L_inv, gain) in enumerate(zip(self._transitions, self._inverse_factors, self._gains)):
            x = Phi @ x
            innovation = columns[s] - x[:self.m]
            out[s] = L_inv @ innovation
            x = x + gain @ innovation
        return out
