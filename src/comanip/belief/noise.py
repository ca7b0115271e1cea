"""Signal-dependent motor noise (docs/formulation.md §2): the command tau is executed as (I + E) tau.

Three forms of the noise covariance N(tau) (n, n) of the executed-torque error E tau, kappa the variance
of each entry of E (dimensionless, so the standard deviation of the error grows in proportion to ||tau||):

- ``isotropic`` (default): E has n×n independent entries, N = kappa ||tau||² I. A push along one axis also
  spreads the hand across it, as the paper's Fig. 4 shows.
- ``per_channel``: E diagonal, N = kappa diag(tau ⊙ tau) (the paper's printed form read channel by channel).
- ``rank_one``: E = eps I with one scalar eps, N = kappa tau tau^T (noise only along the command).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

NOISE_FORMS = ("isotropic", "per_channel", "rank_one")


def check_noise_form(form: str) -> str:
    if form not in NOISE_FORMS:
        raise ValueError(f"noise must be one of {NOISE_FORMS}, got {form!r}")
    return form


def noise_covariance(tau, kappa, form: str = "isotropic"):
    """Covariance N(tau) (n, n) of the torque error E tau; tau (n,) as a CasADi expression or NumPy array."""
    check_noise_form(form)
    if isinstance(tau, (ca.SX, ca.MX, ca.DM)):
        n = tau.shape[0]
        if form == "isotropic":
            return kappa * ca.sumsqr(tau) * ca.DM.eye(n)
        if form == "per_channel":
            return kappa * ca.diag(tau**2)
        return kappa * ca.mtimes(tau, tau.T)
    tau = np.asarray(tau, dtype=float)
    if form == "isotropic":
        return kappa * float(tau @ tau) * np.eye(tau.size)
    if form == "per_channel":
        return kappa * np.diag(tau**2)
    return kappa * np.outer(tau, tau)


def sample_torque_error(tau: np.ndarray, kappa: float, form: str, rng: np.random.Generator) -> np.ndarray:
    """Samples of E tau: tau (..., n) -> (..., n), drawing E as the form says (not from N(tau) directly)."""
    check_noise_form(form)
    tau = np.asarray(tau, dtype=float)
    scale = np.sqrt(kappa)
    if form == "isotropic":
        E = scale * rng.standard_normal(tau.shape + (tau.shape[-1],))
        return np.einsum("...ij,...j->...i", E, tau)
    if form == "per_channel":
        return scale * rng.standard_normal(tau.shape) * tau
    return scale * rng.standard_normal(tau.shape[:-1] + (1,)) * tau
