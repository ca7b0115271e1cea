"""Muscle activation dynamics: a chain of first-order low-pass filters between the motor command and the force.

People cannot step their muscle force: the neural command u passes through activation and force
dynamics with time constants of tens of milliseconds before it moves the arm (Todorov & Jordan 2002;
Li & Todorov 2004; Todorov 2005, whose arm model uses two first-order stages of 40 ms). Here each stage j
of m holds a force-like state a_j (n,), driven by the one before it (the first by the command),

    a_1+ = alpha_1 a_1 + (1 - alpha_1) u,   a_j+ = alpha_j a_j + (1 - alpha_j) a_{j-1},   alpha_j = exp(-h / tau_j)

(each stage the exact step of da/dt = (input - a)/tau_j for an input held over the step), and the last
stage's output is the torque on the body: M(q) qddot + D qdot + G(q) = a_m. The motor noise multiplies the
command (the belief layer executes (I + E) u), so it is low-pass filtered too, as in the papers above.

The state grows to s = [q; qdot; a_1; ...; a_m] (2n + m·n,); the end effector still reads q = s[:n].
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from comanip.bodies.body import Body


class MuscleActuatedBody(Body):
    """A body driven through m first-order activation stages with time constants ``time_constants`` (s).

    Everything but the state and the step is the wrapped body's (inertia, kinematics, limits, home pose).
    The command u (n,) is in the body's torque units (N·m or N): at rest the force equals the command.

    Args:
        body: the rigid body that the filtered force moves.
        time_constants: tau_1..tau_m (s), each finite and > 0; one or two stages are usual.
    """

    def __init__(self, body: Body, time_constants):
        if isinstance(body, MuscleActuatedBody):
            raise ValueError("body already has activation dynamics; wrap the bare body")
        values = tuple(float(t) for t in np.atleast_1d(np.asarray(time_constants, dtype=float)))
        if not values or not all(math.isfinite(t) and t > 0 for t in values):
            raise ValueError(f"activation time constants must be one or more finite numbers > 0 (s), got {time_constants!r}")
        self.inner = body
        self.time_constants = values
        self.n, self.d, self.name = body.n, body.d, body.name
        self.damping = body.damping
        self.joint_limits = body.joint_limits

    @property
    def state_size(self) -> int:
        return (2 + len(self.time_constants)) * self.n

    def mass_matrix(self, q: ca.SX) -> ca.SX:
        return self.inner.mass_matrix(q)

    def end_effector(self, q: ca.SX) -> ca.SX:
        return self.inner.end_effector(q)

    def gravity(self, q: ca.SX) -> ca.SX:
        return self.inner.gravity(q)

    def jacobian(self, q: ca.SX) -> ca.SX:
        return self.inner.jacobian(q)

    def discrete_step(self, s: ca.SX, tau: ca.SX, h: float) -> ca.SX:
        """Mean state after one step: s (2n + m·n,), command tau (n,) -> (2n + m·n,)."""
        n = self.n
        stages = [s[(2 + j) * n:(3 + j) * n] for j in range(len(self.time_constants))]
        body_next = self.inner.discrete_step(s[: 2 * n], stages[-1], h)
        inputs = [tau] + stages[:-1]
        filtered = [math.exp(-h / t) * a + (1 - math.exp(-h / t)) * u
                    for t, a, u in zip(self.time_constants, stages, inputs)]
        return ca.vertcat(body_next, *filtered)

    def command_for_force(self, force: np.ndarray, h: float) -> np.ndarray:
        """Commands (H, n) under which the last stage's output at step k is ``force[k]`` (H, n) at every step k,
        each stage inverted, last to first: input_k = (a_{k+1} - alpha a_k) / (1 - alpha), the last force held.

        Exact when the first m forces are zero (m stages from rest cannot feel a command sooner); otherwise
        the force lags there, which an initial guess tolerates."""
        signal = np.asarray(force, dtype=float)
        for t in reversed(self.time_constants):
            alpha = math.exp(-h / t)
            ahead = np.vstack([signal[1:], signal[-1:]])
            signal = (ahead - alpha * signal) / (1 - alpha)
        return signal

    @property
    def is_linear(self) -> bool:
        return self.inner.is_linear

    @property
    def home_position(self) -> np.ndarray:
        return self.inner.home_position

    def inverse_kinematics(self, x: np.ndarray, q_init: np.ndarray, iterations: int = 100) -> np.ndarray:
        return self.inner.inverse_kinematics(x, q_init, iterations)

    def config(self) -> dict:
        return self.inner.config()
