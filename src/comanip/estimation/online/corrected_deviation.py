"""The belief of a person who corrects deviations from their plan: the plan's errors forgotten over a time constant.

The open-loop belief of a plan (:mod:`comanip.estimation.online.observation_whitening`) takes the state's error about
the plan's mean as a Gauss–Markov process that only grows, e_{i+1} = A e_i + w_i: a hand 1 cm off the plan
at 0.5 s is predicted 1 cm off (or more) at the end. A person who replans from where they are, or whose feedback
pulls them back onto their reach, removes such deviations, so late observations of a hand resting on its goal
say where the goal is, not how far the early errors carried it. Here the deviation is corrected with a time
constant tau (s):

    e_{i+1} = rho A e_i + w_i,   rho = exp(-h / tau),
    Cov(w_i) = Q_i + sigma_t² (1 - rho²) diag_b(|mudot_b,i+1|² I_n),   Q_i = Sigma_{i+1} - A Sigma_i A^T

Q_i are the plan's own noise increments (the motor noise of its commands); the error of the whole state is
pulled back at the rate 1 - rho per step of length h. The second term says that a person strays from the
model's plan by more than its motor noise, by about sigma_t seconds of their current motion in any direction
(ahead of or behind the plan's timing, and across it): mudot_b is the rate of the plan's mean in state block b
(position, velocity, ...); with the factor 1 - rho² its stationary share is about sigma_t² |mudot_b|² per
axis. A hand at rest on its goal (mudot = 0) then carries only the small motor noise, and says where the goal
is; a hand in fast motion says less. The covariance is

    Sigma^c_0 = Sigma_0,   Sigma^c_{i+1} = rho² A Sigma^c_i A^T + Cov(w_i),

bounded instead of growing to the end, and the errors k steps apart have cross covariance (rho A)^k Sigma^c_i:
still a Gauss–Markov process, so :class:`~comanip.estimation.online.observation_whitening.ObservationWhitening`
factors it with the powers (rho A)^k in place of A^k. tau -> infinity (and sigma_t = 0) gives back the
open-loop belief. The mean is the plan's, so an exact observation of a plan still gives back its goal.
"""

from __future__ import annotations

import math

import numpy as np


def correction_factor(correction_time: float, h: float) -> float:
    """rho = exp(-h / tau): the fraction of a deviation left after one step of h s, for a correction time tau (s)."""
    return math.exp(-h / correction_time)


def corrected_powers(A: np.ndarray, rho: float, steps: int) -> np.ndarray:
    """(rho A)^k (steps+1, nx, nx) for k = 0..steps: how an error carries over k steps."""
    decayed = rho * np.asarray(A, dtype=float)
    powers = np.empty((steps + 1,) + decayed.shape)
    powers[0] = np.eye(len(decayed))
    for k in range(1, steps + 1):
        powers[k] = decayed @ powers[k - 1]
    return powers


def corrected_covariance(cov: np.ndarray, A: np.ndarray, rho: float, mean: np.ndarray | None = None,
                         deviation_time=0.0, h: float = 1.0, n: int = 1) -> np.ndarray:
    """Sigma^c_i (H+1, nx, nx) of a corrected deviation, from the plan's open-loop Sigma_i (H+1, nx, nx) and the
    transition A (nx, nx): the module docstring's recursion with the plan's noise increments Q_i (their
    negative eigenvalues, rounding in the plan's covariance, are dropped), plus, for ``deviation_time``
    sigma_t > 0 (s), the speed increments sigma_t² (1 - rho²) |mudot_b,i+1|² I of each state block b (n entries)
    of the plan's mean ``mean`` (H+1, nx) on the grid of step ``h`` (s). ``deviation_time`` may also be one
    sigma_t per axis (n,), or per step and axis (H, n) (step i's increment): diag(sigma_t,a²) in place of
    sigma_t² I (an axis along which the observed motion strays more, e.g. one someone else moves from some time on)."""
    cov = np.asarray(cov, dtype=float)
    A = np.asarray(A, dtype=float)
    increments = cov[1:] - A @ cov[:-1] @ A.T
    increments = 0.5 * (increments + increments.transpose(0, 2, 1))
    values, vectors = np.linalg.eigh(increments)
    increments = (vectors * np.maximum(values, 0.0)[:, None, :]) @ vectors.transpose(0, 2, 1)
    deviation2 = np.broadcast_to(np.square(np.asarray(deviation_time, dtype=float)), (len(cov) - 1, n))
    if np.any(deviation2 > 0):
        rate = np.gradient(np.asarray(mean, dtype=float), h, axis=0)[1:]
        speed2 = np.repeat(np.sum(rate.reshape(len(rate), -1, n) ** 2, axis=2), n, axis=1)      # (H, nx)
        speed2 *= np.tile(deviation2, rate.shape[1] // n)
        increments += (1.0 - rho**2) * speed2[:, :, None] * np.eye(rate.shape[1])
    corrected = np.empty_like(cov)
    corrected[0] = cov[0]
    decayed = rho * A
    for i in range(len(cov) - 1):
        corrected[i + 1] = decayed @ corrected[i] @ decayed.T + increments[i]
    return corrected


def sample_corrected_deviations(cov: np.ndarray, A: np.ndarray, rho: float, mean: np.ndarray, deviation_time,
                                h: float, n: int, count: int, rng: np.random.Generator) -> np.ndarray:
    """Errors (count, H+1, nx) about a plan drawn from the corrected process of :func:`corrected_covariance`
    (same arguments), starting at zero and stepped with the increments its recursion implies,
    Sigma^c_{i+1} - rho² A Sigma^c_i A^T: reaches of a person who corrects, as the belief assumes."""
    corrected = corrected_covariance(cov, A, rho, mean, deviation_time, h, n)
    decayed = rho * np.asarray(A, dtype=float)
    nx = len(decayed)
    errors = np.zeros((count, len(corrected), nx))
    for i in range(len(corrected) - 1):
        increment = corrected[i + 1] - decayed @ corrected[i] @ decayed.T
        factor = np.linalg.cholesky(0.5 * (increment + increment.T) + 1e-18 * np.eye(nx))
        errors[:, i + 1] = errors[:, i] @ decayed.T + rng.normal(size=(count, nx)) @ factor.T
    return errors

