"""The person's estimate of their own arm's state from delayed, noisy feedback: a Kalman filter on the model.

Notation (as comanip.belief.propagation): s_k (nx,) the state, u_k (n,) the command, the step
s_{k+1} = f(s_k, (I + E_k) u_k) with A_k = df/ds, B_k = df/du at the estimate, and process noise
B_k N(u_k) B_k^T (comanip.belief.noise: the motor noise of the known command). The measurement received
after step k is y_{k+1} = C s_{k+1-d} + v, C = [I_2n 0] (it sees [q; qdot], not the activation stages),
v ~ N(0, R) (:class:`comanip.execution.delayed_observation.Observation`), d the delay in steps.

The filter keeps the estimate of the delayed state s_{k+1-d} (mean m, covariance P), corrects it with each
measurement (Joseph form, so P stays symmetric positive semi-definite; a pseudo-inverse of the innovation
covariance so that a noiseless measurement of a state known exactly is allowed), and predicts forward through
the d commands sent since then to give the current state. Before d steps have passed the measurements show
the start, which the person is taken to know exactly (P_0 = 0). For a point mass f is linear and the filter
is exact (A, B taken once): P is the covariance of the estimate's error. For a nonlinear body it is the extended
filter, linearised at the estimate.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from comanip.belief.noise import noise_covariance
from comanip.belief.propagation import linearised_step_function
from comanip.execution.delayed_observation import Observation
from comanip.model import ReachingModel


class DelayedKalmanFilter:
    """Estimate (mean (nx,), cov (nx, nx)) of a model's current state from :class:`Observation` feedback.

    Args:
        model: the person's model (body, h, kappa, noise form); nx = model.state_size.
        observation: the noise and delay of what the person sees.
        start: the start state (nx,), known exactly.
    """

    def __init__(self, model: ReachingModel, observation: Observation, start):
        self.model = model
        self.delay = observation.delay_steps(model.h)
        """d, the delay in steps."""
        self._step = linearised_step_function(model.body, model.h)
        # a linear body (point mass, with or without activation stages) is linearised once: f(s, u) = A s + B u + c
        self._affine = self._linearise(np.zeros(model.state_size), np.zeros(model.n)) if model.body.is_linear else None
        n, nx = model.n, model.state_size
        self._C = np.eye(2 * n, nx)
        self._R = np.diag(observation.noise_std(n) ** 2)
        self._lagged = (np.array(start, dtype=float), np.zeros((nx, nx)))
        self._commands: deque[np.ndarray] = deque()
        self.mean, self.cov = self._lagged
        """Estimate of the current state (nx,) and the covariance of its error (nx, nx)."""

    def update(self, command, measurement) -> np.ndarray:
        """Advance one step with the command u_k (n,) just sent and the measurement y_{k+1} (2n,) just received;
        returns the new estimate of the current state, :attr:`mean` (nx,)."""
        self._commands.append(np.asarray(command, dtype=float))
        mean, cov = self._lagged
        if len(self._commands) > self.delay:
            mean, cov = self._predict(mean, cov, self._commands.popleft())
        self._lagged = mean, cov = self._correct(mean, cov, np.asarray(measurement, dtype=float))
        for u in self._commands:
            mean, cov = self._predict(mean, cov, u)
        self.mean, self.cov = mean, cov
        return mean

    def _linearise(self, mean: np.ndarray, command: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A (nx, nx), B (nx, n), c (nx,)) with f(s, u) ≈ A s + B u + c around (mean (nx,), command (n,))."""
        s_next, A, B = (np.asarray(v) for v in self._step(mean, command))
        return A, B, s_next.ravel() - A @ mean - B @ command

    def _predict(self, mean: np.ndarray, cov: np.ndarray, command: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One time update of mean (nx,), cov (nx, nx) with command (n,): mean+ = f(mean, u),
        cov+ = A cov A^T + B N(u) B^T (for a nonlinear body, linearised at the estimate: the extended filter)."""
        A, B, c = self._affine if self._affine is not None else self._linearise(mean, command)
        process = B @ noise_covariance(command, self.model.kappa, self.model.noise) @ B.T
        return A @ mean + B @ command + c, A @ cov @ A.T + process

    def _correct(self, mean: np.ndarray, cov: np.ndarray, measurement: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One measurement update of mean (nx,), cov (nx, nx) with y (2n,)."""
        C, R = self._C, self._R
        # K = P C^T S^+ with S = C P C^T + R symmetric; the least-squares solution is S^+ (C P) = K^T
        gain = np.linalg.lstsq(C @ cov @ C.T + R, C @ cov, rcond=None)[0].T
        keep = np.eye(len(mean)) - gain @ C
        return mean + gain @ (measurement - C @ mean), keep @ cov @ keep.T + gain @ R @ gain.T
