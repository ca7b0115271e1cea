"""A point mass in n dimensions whose position is its end effector: the paper's planar and Cartesian bodies."""

from __future__ import annotations

import casadi as ca
import numpy as np

from comanip.arguments import as_square_matrix
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
        self.M = as_square_matrix("mass", mass, n, "kg", positive_definite=True)
        self.damping = as_square_matrix("damping", damping, n, "N·s/m")

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
