"""Cartesian impedance control at the torque level, for a torque-controlled arm such as the Panda.

Plain NumPy in, joint torques out: the kinematics and dynamics terms come from whatever backend the caller
has (MuJoCo in :mod:`comanip.simulation`, libfranka's model on a real robot), so the same law runs on both.

Notation: joints q, qdot (n,) in rad, rad/s; TCP position x (3,) m and orientation R (3, 3) in the world
frame; geometric Jacobian J (6, n) with the linear rows first, so [v; omega] = J qdot; joint-space inertia
M (n, n); gravity torque g(q) (n,). The law (Ott 2008, "Cartesian Impedance Control of Redundant and
Flexible-Joint Robots"):

    tau = g(q) + J^T F + N^T tau_0
    F   = K e + D e_dot,  e = [x_r - x;  e_R],  e_R = 1/2 vee(R_r R^T - R R_r^T) = sin(theta) axis
    tau_0 = K_0 (q_r - q) - D_0 qdot,   N^T = I - J^T Jbar^T,  Jbar = M^-1 J^T Lambda

K = diag(k_x, k_y, k_z, k_R, k_R, k_R). D is designed from K and the apparent inertia
Lambda = (J M^-1 J^T)^-1 by double diagonalisation (Albu-Schäffer et al. 2003): each of the six Cartesian
modes gets damping ratio zeta, so a zero stiffness gives zero damping along that direction. There is no
feedforward of the rest motion's acceleration: with a person pushing the same handle toward the same goal,
a robot that also pushes the handle's whole inertia makes the pair overshoot.

Passivity: only gravity is compensated (Coriolis compensation would break the energy balance), the
rotational term is the gradient of the potential k_R (1 - cos theta), and D and D_0 are positive
semi-definite. With no translational or nullspace stiffness, kinetic energy plus that potential never
grows without an external input.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from comanip.arguments import as_nonnegative, as_vector


@dataclass(frozen=True)
class ImpedanceGains:
    """Gains of :class:`CartesianImpedanceController`."""

    translational_stiffness: tuple = (400.0, 400.0, 400.0)
    """Stiffness along world x, y, z (N/m), each ≥ 0; changeable at run time on the controller."""
    rotational_stiffness: float = 60.0
    """Stiffness of the orientation (N·m/rad), ≥ 0; high, so the carried object keeps its attitude."""
    damping_ratio: float = 1.0
    """Damping ratio zeta of every Cartesian mode (dimensionless), ≥ 0; 1 is critical damping."""
    nullspace_stiffness: float = 10.0
    """Stiffness pulling the joints toward the rest posture inside the task's nullspace (N·m/rad), ≥ 0."""
    nullspace_damping_ratio: float = 1.0
    """Damping ratio of the nullspace term per joint, relative to the joint's own inertia M_ii, ≥ 0."""

    def __post_init__(self):
        stiffness = as_vector("translational_stiffness", self.translational_stiffness, 3, "N/m per world axis")
        if np.any(stiffness < 0):
            raise ValueError(f"translational_stiffness must be ≥ 0 N/m on every axis, got {stiffness.tolist()}")
        object.__setattr__(self, "translational_stiffness", tuple(stiffness.tolist()))
        as_nonnegative("rotational_stiffness", self.rotational_stiffness, "N·m/rad")
        as_nonnegative("damping_ratio", self.damping_ratio, "dimensionless")
        as_nonnegative("nullspace_stiffness", self.nullspace_stiffness, "N·m/rad")
        as_nonnegative("nullspace_damping_ratio", self.nullspace_damping_ratio, "dimensionless")


@dataclass
class RobotState:
    """What the controller needs from a kinematics backend at one instant. n joints."""

    q: np.ndarray
    """Joint positions (n,), rad."""
    qdot: np.ndarray
    """Joint velocities (n,), rad/s."""
    position: np.ndarray
    """TCP position (3,), m, world frame."""
    rotation: np.ndarray
    """TCP orientation (3, 3), world frame."""
    jacobian: np.ndarray
    """Geometric Jacobian (6, n): linear rows then angular rows, world frame."""
    mass_matrix: np.ndarray
    """Joint-space inertia M(q) (n, n), kg·m²."""
    gravity: np.ndarray
    """Gravity torque g(q) (n,), N·m, of the arm alone (the controller's model)."""

    @cached_property
    def velocity(self) -> np.ndarray:
        """TCP linear velocity (3,), m/s."""
        return self.jacobian[:3] @ self.qdot


class CartesianImpedanceController:
    """Torque-level Cartesian impedance law (module docstring) with run-time translational stiffness.

    Args:
        gains: the gains; the translational stiffness can change later through :attr:`translational_stiffness`.
        rest_posture: joint posture q_r (n,) the nullspace term pulls toward, rad.
        torque_limit: symmetric joint torque limits (n,), N·m; commands are clipped to them (None: no clipping).
        redesign_angle: the configuration-dependent parts (the damping design, an eigen-decomposition, and
            the nullspace projector: most of a call's cost) are redone when the stiffness changes or some
            joint has moved more than this (rad) since the last design; the apparent inertia changes by
            about 1 % in between. 0 redesigns on every call.

    >>> controller = CartesianImpedanceController(ImpedanceGains(), rest_posture=q0, torque_limit=limits)
    >>> controller.translational_stiffness = [0, 0, 400]
    >>> tau = controller(state, position_rest=x_r, rotation_rest=R_r)
    """

    def __init__(self, gains: ImpedanceGains, rest_posture, torque_limit=None, redesign_angle: float = 0.02):
        if not isinstance(gains, ImpedanceGains):
            raise ValueError(f"gains must be an ImpedanceGains, got {type(gains).__name__}")
        self.gains = gains
        self.rest_posture = np.array(rest_posture, dtype=float)
        n = self.rest_posture.size
        self.torque_limit = None if torque_limit is None else as_vector("torque_limit", torque_limit, n, "N·m")
        self.redesign_angle = as_nonnegative("redesign_angle", redesign_angle, "rad")
        self._stiffness = np.r_[gains.translational_stiffness, np.full(3, gains.rotational_stiffness)]
        self._damping = None
        self._designed_at = np.full(n, np.inf)
        self.last_force = np.zeros(3)
        """The translational part of the last commanded wrench K e + D e_dot (3,), N: the force the
        impedance applies at the TCP (before any torque clipping)."""

    @property
    def translational_stiffness(self) -> np.ndarray:
        """Current stiffness along world x, y, z (3,), N/m."""
        return self._stiffness[:3].copy()

    @translational_stiffness.setter
    def translational_stiffness(self, value) -> None:
        stiffness = as_vector("translational_stiffness", value, 3, "N/m per world axis")
        if np.any(stiffness < 0):
            raise ValueError(f"translational_stiffness must be ≥ 0 N/m on every axis, got {stiffness.tolist()}")
        if np.any(stiffness != self._stiffness[:3]):
            self._stiffness[:3] = stiffness
            self._damping = None

    def reset(self) -> None:
        """Forget the configuration-dependent design (the next call redesigns at its state), so runs that
        start from the same state compute the same torques whatever ran before."""
        self._damping = None
        self._designed_at = np.full(len(self.rest_posture), np.inf)
        self.last_force = np.zeros(3)

    def __call__(self, state: RobotState, position_rest, rotation_rest, velocity_rest=None) -> np.ndarray:
        """Joint torques (n,), N·m, for the rest pose (position_rest (3,) m, rotation_rest (3, 3)) moving at
        velocity_rest (3,) m/s (zero when None)."""
        g = self.gains
        J, q, qdot = state.jacobian, state.q, state.qdot
        if self._damping is None or np.max(np.abs(q - self._designed_at)) > self.redesign_angle:
            self._design(state)
        error = np.concatenate((np.asarray(position_rest) - state.position, orientation_error(rotation_rest, state.rotation)))
        twist_error = -(J @ qdot)
        if velocity_rest is not None:
            twist_error[:3] += velocity_rest
        wrench = self._stiffness * error + self._damping @ twist_error
        self.last_force = wrench[:3].copy()
        tau_0 = g.nullspace_stiffness * (self.rest_posture - q) - self._nullspace_damping * qdot
        tau = state.gravity + J.T @ wrench + self._nullspace_projector @ tau_0
        if self.torque_limit is not None:
            tau = np.minimum(np.maximum(tau, -self.torque_limit), self.torque_limit)
        return tau

    def _design(self, state: RobotState) -> None:
        """The configuration-dependent parts, refreshed when the joints have moved (see redesign_angle): the
        modal damping D, the nullspace damping 2 zeta_0 sqrt(K_0 M_ii), and the dynamically consistent
        projector N^T = I - J^T Lambda J M^-1, with which the posture torque produces no task-space
        acceleration."""
        J, M, g = state.jacobian, state.mass_matrix, self.gains
        M_inv_JT = np.linalg.solve(M, J.T)
        Lambda_inv = J @ M_inv_JT
        self._damping = modal_damping(Lambda_inv, self._stiffness, g.damping_ratio)
        self._nullspace_projector = np.eye(len(state.q)) - J.T @ np.linalg.solve(Lambda_inv, M_inv_JT.T)
        self._nullspace_damping = 2.0 * g.nullspace_damping_ratio * np.sqrt(g.nullspace_stiffness * M.diagonal())
        self._designed_at = state.q.copy()


def orientation_error(rotation_rest: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """e_R = 1/2 vee(R_r R^T - R R_r^T) = sin(theta) axis (3,): the world-frame rotation that takes R to R_r,
    as the negative gradient of the potential 1 - cos(theta)."""
    E = rotation_rest @ rotation.T
    return 0.5 * np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])


def modal_damping(Lambda_inv: np.ndarray, stiffness: np.ndarray, zeta: float) -> np.ndarray:
    """Damping D (m, m) that gives every mode of Lambda xddot + D xdot + diag(stiffness) x = 0 the damping
    ratio zeta, for the apparent inertia Lambda = Lambda_inv^-1.

    Lambda_inv = J M^-1 J^T (m, m) positive definite; stiffness (m,) ≥ 0. Double diagonalisation
    (Albu-Schäffer et al. 2003) through the Cholesky factor Lambda_inv = R R^T, so Lambda = R^-T R^-1:
    R^T K R = Y diag(w) Y^T gives the modes and D = R^-T Y diag(2 zeta sqrt(w)) Y^T R^-1 (positive
    semi-definite; zero along directions without stiffness).
    """
    R = np.linalg.cholesky(Lambda_inv)
    scaled = np.sqrt(stiffness)[:, None] * R
    w, Y = np.linalg.eigh(scaled.T @ scaled)
    modes = np.linalg.solve(R.T, Y)
    return (modes * (2.0 * zeta * np.sqrt(np.maximum(w, 0.0)))) @ modes.T
