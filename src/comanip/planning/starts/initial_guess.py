"""Initial guesses: minimum-jerk reaches (Flash & Hogan 1985) turned into torques by inverse dynamics.

The zero-torque guess is a trap: far from a narrow goal the expected reward underflows, its gradient is
~0, and a solver stops at once with the arm at rest (docs/formulation.md §9). A smooth reach of a chosen duration starts
the solver where the reward is felt; the duration selects among the local optima.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import casadi as ca
import numpy as np

from comanip.bodies.body import Body
from comanip.caching.buffered_function import BufferedFunction
from comanip.caching.process_caches import memoised


class Quintic(NamedTuple):
    """A quintic profile sampled at times (:func:`minimum_jerk`)."""

    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def minimum_jerk(x0, v0, x1, duration, t) -> Quintic:
    """Quintic from x0 (k,) at velocity v0 (k,), zero acceleration, to rest at x1 (k,) after duration (s).

    Returns position, velocity, acceleration, each (len(t), k); held at x1 after the duration. ``duration``
    may also be durations (m,), one profile each: the outputs are then (m, len(t), k).
    With v0 = 0 this is the Flash–Hogan minimum-jerk profile (peak speed at mid-movement).
    """
    durations = np.asarray(duration, dtype=float)
    pos, vel, acc = _quintic(x0, v0, x1, _QuinticTimes(durations, np.asarray(t, dtype=float)))
    return Quintic(pos, vel, acc) if durations.ndim else Quintic(pos[0], vel[0], acc[0])


class _QuinticTimes:
    """The parts of :func:`minimum_jerk` that depend on the durations (m,) and times (K,) alone: powers of the
    durations T and of the clipped times tc = min(max(t, 0), T), and where t is past T. A planner's guesses
    use the same durations and steps every solve (:func:`_step_times` keeps them)."""

    def __init__(self, durations: np.ndarray, t: np.ndarray):
        T = self.T = durations.reshape(-1, 1, 1)  # (m, 1, 1)
        self.powers = np.stack([T**3, T**4, T**5])  # (3, m, 1, 1)
        tc = self.tc = np.minimum(np.maximum(t, 0.0)[None, :, None], T)  # (m, K, 1)
        self.tc2, self.tc3 = tc**2, tc**3
        self.tc_scaled = np.stack([tc * 5, tc * 20])  # (2, m, K, 1): the a5 factors of velocity and acceleration
        self.after = t[None, :] > T[:, :, 0]


_COEFFICIENTS = np.array([[10.0, -15.0, 6.0], [6.0, -8.0, 3.0]]).reshape(2, 3, 1, 1, 1)
"""The quintic's coefficients a3, a4, a5 = (c·delta - c'·v0·T) / (T³, T⁴, T⁵): rows c and c'."""
_DERIVATIVE_FACTORS = np.array([[3.0, 6.0], [4.0, 12.0]]).reshape(2, 2, 1, 1, 1)
"""The factors of a3 (first row) and a4 (second row) in the velocity and the acceleration."""


@memoised(maxsize=32)
def _step_times(durations: tuple[float, ...], h: float, H: int) -> _QuinticTimes:
    """:class:`_QuinticTimes` of the durations (s) at the steps t_i = h·i, i < H, built once per arguments."""
    return _QuinticTimes(np.array(durations), h * np.arange(H))


def _quintic(x0, v0, x1, times: _QuinticTimes, positions: bool = True) -> tuple[np.ndarray | None, np.ndarray, np.ndarray]:
    """Position (None unless ``positions``), velocity and acceleration (m, K, k) of :func:`minimum_jerk` for every
    duration of ``times``.

    Velocity and acceleration are computed side by side (stacked on a first axis), each entry by the same
    floating-point operations as the formulas in the comments (x - (-y) is x + y exactly)."""
    x0, v0, x1 = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (x0, v0, x1))
    tc = times.tc
    # the quintic's coefficients in closed form (x(0) = x0, x'(0) = v0, x''(0) = 0, x(T) = x1, x'(T) = x''(T) = 0):
    # a3 = (10 delta - 6 v0 T) / T³, a4 = (-15 delta + 8 v0 T) / T⁴, a5 = (6 delta - 3 v0 T) / T⁵
    a3, a4, a5 = (_COEFFICIENTS[0] * (x1 - x0) - _COEFFICIENTS[1] * v0 * times.T) / times.powers
    # velocity v0 + tc² (3 a3 + tc (4 a4 + tc·5 a5)), acceleration tc (6 a3 + tc (12 a4 + tc·20 a5))
    inner = _DERIVATIVE_FACTORS[1] * a4 + times.tc_scaled * a5
    outer = _DERIVATIVE_FACTORS[0] * a3 + tc * inner
    vel = v0 + times.tc2 * outer[0]
    acc = tc * outer[1]
    pos = x0 + v0 * tc + times.tc3 * (a3 + tc * (a4 + tc * a5)) if positions else None
    vel[times.after] = 0.0
    acc[times.after] = 0.0
    return pos, vel, acc


def minimum_jerk_torques(body: Body, h: float, H: int, start: np.ndarray, goal_q: np.ndarray, duration,
                         linear_dynamics: LinearDynamics | None = None) -> np.ndarray:
    """Commands (H, n) that make the mean follow a joint-space minimum-jerk reach from start (nx,) to goal_q (n,)
    (through the body's activation stages, if it has them); for durations (m,), one per duration (m, H, n), to
    goal_q (n,) or to a goal per duration (m, 1, n).

    ``linear_dynamics``: a linear body's constant M and G from :func:`linear_dynamics_of` (its start policy's); None
    for a nonlinear body, whose M(q) and G(q) are evaluated along the path."""
    durations = np.asarray(duration, dtype=float)
    q, qdot, qddot = _quintic(start[: body.n], start[body.n:2 * body.n], goal_q,
                              _step_times(tuple(durations.ravel().tolist()), h, H), positions=linear_dynamics is None)
    if not durations.ndim:
        q, qdot, qddot = None if q is None else q[0], qdot[0], qddot[0]
    if linear_dynamics is not None:  # constant M and G: inverse dynamics of all steps (and durations) at once
        force = qddot @ linear_dynamics.mass.T + qdot @ body.damping.T + linear_dynamics.gravity
        return np.array([body.command_for_force(f, h) for f in force]) if force.ndim == 3 else body.command_for_force(force, h)
    if q.ndim == 3:
        return np.array([_arm_torques(body, h, H, *profile) for profile in zip(q, qdot, qddot)])
    return _arm_torques(body, h, H, q, qdot, qddot)


def _arm_torques(body: Body, h: float, H: int, q, qdot, qddot) -> np.ndarray:
    """Commands (H, n) for a joint path q, qdot, qddot (H, n) of a nonlinear body: M(q_i) and G(q_i) of all steps
    in one call each (a Python loop over the steps took ~50 ms on the Panda)."""
    M = _mass_matrices(body, q)
    G = _along(body.gravity_function, H)(q.T)[0].T
    return body.command_for_force(np.einsum("irs,is->ir", M, qddot) + qdot @ body.damping.T + G, h)


@dataclass(frozen=True)
class LinearDynamics:
    """A linear body's mass matrix and gravity, the same at every q."""

    mass: np.ndarray
    """M (n, n)."""
    gravity: np.ndarray
    """G (n,)."""


def linear_dynamics_of(body: Body) -> LinearDynamics:
    """The constant M and G of a linear body."""
    q = np.zeros(body.n)
    return LinearDynamics(np.asarray(body.mass_matrix_function(q)), np.asarray(body.gravity_function(q)).ravel())


def retargeted_torques(body: Body, h: float, H: int, torque: np.ndarray, shift_q: np.ndarray, durations,
                       mean: np.ndarray | None = None,
                       linear_dynamics: LinearDynamics | None = None) -> list[np.ndarray]:
    """A plan's torques (H, n) with a rest-to-rest minimum-jerk move by shift_q (n,) superposed, one result
    per duration (s): delta tau = M(q_i) delta qddot_i + D delta qdot_i along the plan's mean (H+1, 2n).

    For a linear body the mean is affine in the torques, so each result moves the whole planned mean path
    by a smooth reach of shift_q: a plan for one goal becomes a good start for a nearby goal (far fewer Newton
    iterations than the unmodified plan: docs/results/speed.md). For a nonlinear
    body (M evaluated along ``mean``, required then) it holds to first order. ``linear_dynamics``: as for
    :func:`minimum_jerk_torques`.
    """
    if linear_dynamics is not None:
        inertia = np.broadcast_to(linear_dynamics.mass, (H, body.n, body.n))
    elif mean is None:
        raise ValueError(f"retargeting a plan of a nonlinear body ({body.name!r}) needs its mean path")
    else:
        inertia = _mass_matrices(body, mean[:H, : body.n])
    T = np.asarray(durations, dtype=float)[:, None]
    s = np.clip(h * np.arange(H) / T, 0.0, 1.0)  # (durations, H)
    # x(t) = shift_q (10 s³ - 15 s⁴ + 6 s⁵): Flash–Hogan from rest to rest, all durations at once
    speed = 30 * s**2 * (1 - s) ** 2 / T
    acceleration = 60 * s * (1 - s) * (1 - 2 * s) / T**2
    return _superposed(body, h, torque, inertia, shift_q, speed, acceleration)


def braked_torques(body: Body, h: float, H: int, torque: np.ndarray, velocity: np.ndarray, durations,
                   mean: np.ndarray) -> list[np.ndarray]:
    """A plan's torques (H, n) from rest with a minimum-jerk move from the start velocity ``velocity`` (n,) back to
    rest at the start position superposed, one result per duration (s): delta tau = M(q_i) delta qddot_i +
    D delta qdot_i along the plan's mean (H+1, nx). Started at that velocity, the body then follows nearly the plan
    (the move is continuous-time, the step forward Euler; for a nonlinear body also to first order): a plan from
    rest becomes a start for the same reach from a moving start (on 20 moving franka_rest starts, 15 instead of
    86 Newton iterations, :func:`brake_durations`)."""
    # the move is velocity·sigma(t): sigma the unit quintic from speed 1 to rest, all durations at once
    _, speed, acceleration = minimum_jerk(0.0, 1.0, 0.0, np.asarray(durations, dtype=float), h * np.arange(H))
    return _superposed(body, h, torque, _mass_matrices(body, mean[:H, : body.n]), velocity, speed[..., 0],
                       acceleration[..., 0])


def brake_durations(horizon_s: float) -> np.ndarray:
    """Durations (s) of the braking moves of :func:`braked_torques`: a sixth and a third of the horizon (on 20
    moving franka_rest starts: 15 median Newton iterations, against 16.5 for a quarter and three quarters)."""
    return np.array([1 / 6, 1 / 3]) * horizon_s


@memoised(maxsize=32)
def guess_durations(horizon_s: float, count: int) -> np.ndarray:
    """Reach durations (s) to try as initial guesses: spread over 25 %–75 % of the horizon (read only: one
    array per arguments, shared by every caller)."""
    durations = np.array([0.5 * horizon_s]) if count == 1 else np.linspace(0.25, 0.75, count) * horizon_s
    durations.flags.writeable = False
    return durations


def _superposed(body: Body, h: float, torque: np.ndarray, inertia: np.ndarray, direction: np.ndarray,
                speed: np.ndarray, acceleration: np.ndarray) -> list[np.ndarray]:
    """torque (H, n) plus the commands of the joint motion direction (n,)·sigma(t), one result per row of the
    profiles speed = sigma' and acceleration = sigma'' (m, H): delta tau_i = M_i direction sigma''_i +
    D direction sigma'_i, with M_i = inertia (H, n, n) along the plan."""
    forces = acceleration[:, :, None] * (inertia @ direction) + speed[:, :, None] * (body.damping @ direction)
    return [torque + body.command_for_force(force, h) for force in forces]


def _mass_matrices(body: Body, q: np.ndarray) -> np.ndarray:
    """M(q_k) (K, n, n) at joint positions q (K, n), in one call."""
    K, n = q.shape
    return _along(body.mass_matrix_function, K)(q.T)[0].reshape(n, K, n).transpose(1, 0, 2)


@memoised(maxsize=32)
def _along(function: ca.Function, steps: int) -> BufferedFunction:
    """``function`` mapped over ``steps`` columns, built once per (function, steps) and called without DM
    conversions (building the map and converting cost ~1 ms a call on the Panda, more than the evaluation)."""
    return BufferedFunction(function.map(steps))
