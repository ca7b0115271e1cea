"""The body interface every layer above speaks: inertia, damping, kinematics, one discrete step.

Notation (shared with the rest of comanip): joint (or Cartesian) position q (n,), velocity qdot (n,),
state s = [q; qdot] (2n,), control tau (n,) in N·m or N, end-effector position x = x_ee(q) (d,) in m,
Jacobian J(q) = dx_ee/dq (d, n), step h in s.

A body is written once as CasADi expressions. The belief layer linearises `discrete_step` with CasADi, so
a nonlinear body (the Panda) plugs in by overriding the few methods below; nothing above changes.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from functools import cached_property

import casadi as ca
import numpy as np


class Body(ABC):
    """A rigid body model: ``M(q) qddot + D qdot + G(q) = tau``.

    Subclasses set ``n`` (degrees of freedom), ``d`` (task-space dimension) and ``name``, and implement
    :meth:`mass_matrix`, :meth:`end_effector`. Everything else has a default that holds for any body.
    """

    n: int
    d: int
    name: str

    #: Damping D (n, n), N·m·s/rad or N·s/m.
    damping: np.ndarray

    @abstractmethod
    def mass_matrix(self, q: ca.SX) -> ca.SX:
        """Inertia M(q) (n, n), kg·m² or kg, as a CasADi expression of q (n,)."""

    @abstractmethod
    def end_effector(self, q: ca.SX) -> ca.SX:
        """End-effector position x_ee(q) (d,), m, as a CasADi expression of q (n,)."""

    def gravity(self, q: ca.SX) -> ca.SX:
        """Gravity torque G(q) (n,). Zero by default: point masses, and arms whose controller compensates it."""
        return ca.SX.zeros(self.n)

    def jacobian(self, q: ca.SX) -> ca.SX:
        """Translational Jacobian J(q) = dx_ee/dq (d, n)."""
        return ca.jacobian(self.end_effector(q), q)

    def discrete_step(self, s: ca.SX, tau: ca.SX, h: float) -> ca.SX:
        """Mean state after one forward-Euler step of length h (s): s (2n,), tau (n,) -> (2n,).

        qddot = M(q)^-1 (tau - D qdot - G(q)); q+ = q + h qdot; qdot+ = qdot + h qddot.

        M is symmetric positive definite, so the solve is an LDLᵀ factorisation (``ca.ldl``): for the Panda its
        step with Jacobians is a third fewer operations than CasADi's general symbolic QR (``ca.solve``), and
        every evaluation of the belief and its derivatives is that much cheaper (benchmarks/warm_breakdown.py times it).
        """
        q, qdot = s[: self.n], s[self.n :]
        D, Lt, p = ca.ldl(self.mass_matrix(q))
        qddot = ca.ldl_solve(tau - ca.mtimes(self.damping, qdot) - self.gravity(q), D, Lt, p)
        return ca.vertcat(q + h * qdot, qdot + h * qddot)

    def step_function(self, h: float) -> ca.Function:
        """Numeric :meth:`discrete_step` of length h (s): ``(s (state_size,), tau (n,)) -> s_next (state_size,)``."""
        s, tau = ca.SX.sym("s", self.state_size), ca.SX.sym("tau", self.n)
        return ca.Function("step", [s, tau], [self.discrete_step(s, tau, h)])

    def command_for_force(self, force: np.ndarray, h: float) -> np.ndarray:
        """Commands (H, n) under which the body feels the torques ``force`` (H, n): the same, for a bare body."""
        return np.asarray(force, dtype=float)

    @property
    def state_size(self) -> int:
        """Length of the state s: 2n, [q; qdot], for a rigid body (bodies with actuator states add theirs)."""
        return 2 * self.n

    @property
    def is_linear(self) -> bool:
        """True when M is constant and x_ee is linear, so the belief dynamics are exactly LTI."""
        return False

    @cached_property
    def kinematics_function(self) -> ca.Function:
        """Numeric ``(q (n,)) -> (x_ee (d,), J (d, n))``."""
        q = ca.SX.sym("q", self.n)
        return ca.Function("kinematics", [q], [self.end_effector(q), self.jacobian(q)], ["q"], ["x", "J"])

    @cached_property
    def mass_matrix_function(self) -> ca.Function:
        """Numeric ``(q (n,)) -> M (n, n)``."""
        q = ca.SX.sym("q", self.n)
        return ca.Function("M", [q], [self.mass_matrix(q)], ["q"], ["M"])

    @cached_property
    def gravity_function(self) -> ca.Function:
        """Numeric ``(q (n,)) -> G (n,)``."""
        q = ca.SX.sym("q", self.n)
        return ca.Function("G", [q], [self.gravity(q)], ["q"], ["G"])

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
        """Torque (n,) that produces acceleration qddot at (q, qdot): M(q) qddot + D qdot + G(q)."""
        M = np.asarray(self.mass_matrix_function(q))
        G = np.asarray(self.gravity_function(q)).ravel()
        return M @ qddot + self.damping @ qdot + G

    def inverse_kinematics(self, x: np.ndarray, q_init: np.ndarray, iterations: int = 100) -> np.ndarray:
        """Joint position (n,) whose end effector is nearest x (d,), m, by damped least squares from q_init."""
        return self.least_squares_inverse_kinematics(x, q_init, iterations)

    def least_squares_inverse_kinematics(self, x: np.ndarray, q_init: np.ndarray, iterations: int) -> np.ndarray:
        """Joint position (n,) after at most ``iterations`` damped least-squares steps of the end effector from
        q_init (n,) towards x (d,), m, each clipped to the joint limits (a body may find its nearest point
        otherwise: :meth:`inverse_kinematics`)."""
        q = np.array(q_init, dtype=float)
        for _ in range(iterations):
            x_q, J = (np.asarray(v) for v in self.kinematics_function(q))
            error = np.asarray(x, dtype=float) - x_q.ravel()
            if np.linalg.norm(error) < 1e-9:
                break
            q = q + J.T @ np.linalg.solve(J @ J.T + 1e-6 * np.eye(self.d), error)
            q = self.clip_to_limits(q)
        return q

    #: Joint limits as {"q_min", "q_max", "qdot_max", "tau_max"} -> (n,) arrays; None for a body without
    #: limits, whose limit properties are then infinite.
    joint_limits: dict[str, np.ndarray] | None = None

    def _limit(self, key: str, unbounded: float) -> np.ndarray:
        if self.joint_limits is None:
            return np.full(self.n, unbounded)
        return np.array(self.joint_limits[key], dtype=float)

    @property
    def q_min(self) -> np.ndarray:
        """Lower position limits (n,), rad or m; -inf (no limit) unless the body has joint limits."""
        return self._limit("q_min", -np.inf)

    @property
    def q_max(self) -> np.ndarray:
        """Upper position limits (n,), rad or m; +inf (no limit) unless the body has joint limits."""
        return self._limit("q_max", np.inf)

    @property
    def qdot_max(self) -> np.ndarray:
        """Speed limits (n,), rad/s or m/s, symmetric (|qdot| <= qdot_max); +inf unless the body has limits."""
        return self._limit("qdot_max", np.inf)

    @property
    def tau_max(self) -> np.ndarray:
        """Torque or force limits (n,), N·m or N, symmetric (|tau| <= tau_max); +inf unless the body has limits."""
        return self._limit("tau_max", np.inf)

    @property
    def home_position(self) -> np.ndarray:
        """Position q (n,) the body rests in before a reach (the default start): the origin unless overridden."""
        return np.zeros(self.n)

    def clip_to_limits(self, q: np.ndarray) -> np.ndarray:
        """q (n,) clipped to [q_min, q_max]; unchanged for a body without limits."""
        return np.clip(q, self.q_min, self.q_max)

    @abstractmethod
    def config(self) -> dict:
        """The body's parameters as plain data with a ``type`` key (for YAML); see :func:`comanip.bodies.body_from_config`."""
