"""Mean and covariance of the state under signal-dependent motor noise (docs/formulation.md §2, paper eq. 6).

s_i ~ N(mu_i, Sigma_i), mu_0 = s_0, Sigma_0 = 0, and for i = 0..H-1, with f the body's discrete step:

    mu_{i+1}    = f(mu_i, tau_i)
    Sigma_{i+1} = A_i Sigma_i A_i^T + B_i N(tau_i) B_i^T,   A_i = df/ds, B_i = df/dtau at (mu_i, tau_i)

For a point mass f is linear and A, B are the paper's matrices. The same step is offered as a CasADi
function (for the optimiser) and as a NumPy rollout (for analysis and as an independent check).
Shapes: s, mu (nx,); Sigma (nx, nx); tau (n,); trajectories stack steps on the first axis. nx is the
body's state size: 2n for [q; qdot], plus n per muscle activation stage (comanip.bodies.muscle), where the
noise enters at the command and reaches the force through the filter.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from comanip.belief.noise import check_noise_form, noise_covariance, sample_torque_error
from comanip.bodies.body import Body


def linearised_step_function(body: Body, h: float) -> ca.Function:
    """``(s (nx,), tau (n,)) -> (f(s, tau) (nx,), A (nx, nx), B (nx, n))``: one step and its Jacobians."""
    s = ca.SX.sym("s", body.state_size)
    tau = ca.SX.sym("tau", body.n)
    s_next = body.discrete_step(s, tau, h)
    A = ca.jacobian(s_next, s)
    B = ca.jacobian(s_next, tau)
    return ca.Function("linearised_step", [s, tau], [s_next, A, B], ["s", "tau"], ["s_next", "A", "B"])


def belief_step_function(body: Body, h: float, kappa: float, noise: str = "isotropic") -> ca.Function:
    """``(mu (nx,), Sigma (nx, nx), tau (n,)) -> (mu+ (nx,), Sigma+ (nx, nx))`` as a CasADi function."""
    check_noise_form(noise)
    step = linearised_step_function(body, h)
    mu = ca.SX.sym("mu", body.state_size)
    Sigma = ca.SX.sym("Sigma", body.state_size, body.state_size)
    tau = ca.SX.sym("tau", body.n)
    mu_next, A, B = step(mu, tau)
    Sigma_next = ca.mtimes([A, Sigma, A.T]) + ca.mtimes([B, noise_covariance(tau, kappa, noise), B.T])
    return ca.Function("belief_step", [mu, Sigma, tau], [mu_next, Sigma_next], ["mu", "Sigma", "tau"], ["mu_next", "Sigma_next"])


def end_effector_belief_function(body: Body) -> ca.Function:
    """``(mu (nx,), Sigma (nx, nx)) -> (mu_x (d,), Sigma_x (d, d))``: mu_x = x_ee(mu_q), Sigma_x = J Sigma_qq J^T."""
    mu = ca.SX.sym("mu", body.state_size)
    Sigma = ca.SX.sym("Sigma", body.state_size, body.state_size)
    q = mu[: body.n]
    J = body.jacobian(q)
    Sigma_x = ca.mtimes([J, Sigma[: body.n, : body.n], J.T])
    return ca.Function("ee_belief", [mu, Sigma], [body.end_effector(q), Sigma_x], ["mu", "Sigma"], ["mu_x", "Sigma_x"])


def propagate_belief(body: Body, h: float, kappa: float, s0, torque, noise: str = "isotropic"):
    """NumPy rollout of the belief: s0 (nx,), torque (H, n) -> mean (H+1, nx), cov (H+1, nx, nx)."""
    check_noise_form(noise)
    step = linearised_step_function(body, h)
    torque = np.atleast_2d(np.asarray(torque, dtype=float))
    mean = np.zeros((len(torque) + 1, body.state_size))
    cov = np.zeros((len(torque) + 1, body.state_size, body.state_size))
    mean[0] = s0
    for i, tau in enumerate(torque):
        s_next, A, B = (np.asarray(v) for v in step(mean[i], tau))
        mean[i + 1] = s_next.ravel()
        cov[i + 1] = A @ cov[i] @ A.T + B @ noise_covariance(tau, kappa, noise) @ B.T
    return mean, cov


def end_effector_belief(body: Body, mean, cov):
    """Task-space belief of a state trajectory: mean (T, nx), cov (T, nx, nx) -> (T, d), (T, d, d)."""
    f = end_effector_belief_function(body)
    pairs = [f(m, c) for m, c in zip(mean, cov)]
    return np.array([np.asarray(x).ravel() for x, _ in pairs]), np.array([np.asarray(S) for _, S in pairs])


def sample_trajectories(body: Body, h: float, kappa: float, s0, torque, n_samples: int, rng, noise: str = "isotropic"):
    """Monte Carlo of the noisy discrete dynamics s+ = f(s, (I + E) tau), open loop.

    s0 (nx,), torque (H, n) -> states (n_samples, H+1, nx). Each sample draws its own E at every step.
    """
    check_noise_form(noise)
    step = body.step_function(h).map(n_samples)
    torque = np.atleast_2d(np.asarray(torque, dtype=float))
    states = np.zeros((n_samples, len(torque) + 1, body.state_size))
    states[:, 0] = s0
    for i, tau_i in enumerate(torque):
        executed = tau_i + sample_torque_error(np.broadcast_to(tau_i, (n_samples, body.n)), kappa, noise, rng)
        states[:, i + 1] = np.asarray(step(states[:, i].T, executed.T)).T
    return states
