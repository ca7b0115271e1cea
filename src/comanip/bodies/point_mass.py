"""A point mass in n dimensions whose position is its end effector: the paper's planar and Cartesian bodies."""

from __future__ import annotations

import casadi as ca
import numpy as np

from comanip.bodies.body import Body


class PointMass(Body):
    """Point mass with constant inertia M (n, n) kg and damping D (n, n) N·s/m; x_ee(q) = q, so d = n.

    Args:
        mass: M as a scalar (kg, times the identity) or an (n, n) symmetric positive-definite matrix.
        damping: D as a scalar (N·s/m, times the identity) or an (n, n) matrix.
        n: dimension, 2 (planar) or 3 (Cartesian); needed when both are scalars.
    """

    def __init__(self, n: int, mass: float | np.ndarray = 2.0, damping: float | np.ndarray = 0.3):
        if n not in (1, 2, 3):
            raise ValueError(f"n must be 1, 2 or 3 (point-mass dimension), got {n!r}")
        self.n = self.d = n
        self.name = {1: "line", 2: "planar", 3: "cartesian"}[n]
        self.M = _as_matrix("mass", mass, n, positive_definite=True)
        self.damping = _as_matrix("damping", damping, n, positive_definite=False)

    def mass_matrix(self, q: ca.SX) -> ca.SX:
        return ca.SX(self.M)

    def end_effector(self, q: ca.SX) -> ca.SX:
        return q

    def jacobian(self, q: ca.SX) -> ca.SX:
        return ca.SX.eye(self.n)

    @property
    def is_linear(self) -> bool:
        return True

    def inverse_kinematics(self, x: np.ndarray, q_init: np.ndarray, iterations: int = 0) -> np.ndarray:
        return np.array(x, dtype=float)

    def config(self) -> dict:
        return {"type": "point_mass", "n": self.n, "mass": self.M.tolist(), "damping": self.damping.tolist()}


def _as_matrix(name: str, value, n: int, positive_definite: bool) -> np.ndarray:
    matrix = np.asarray(value, dtype=float)
    if matrix.ndim == 0:
        matrix = float(matrix) * np.eye(n)
    if matrix.shape != (n, n) or not np.all(np.isfinite(matrix)):
        raise ValueError(f"{name} must be a finite scalar or ({n}, {n}) matrix, got shape {matrix.shape}")
    if positive_definite and (not np.allclose(matrix, matrix.T) or np.linalg.eigvalsh(matrix).min() <= 0):
        raise ValueError(f"{name} must be symmetric positive definite, got {matrix.tolist()}")
    return matrix
