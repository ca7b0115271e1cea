"""A planned reach as the impedance controller's rest motion (docs/formulation.md §8: the plan's mean is the rest position).

The plan gives the mean end effector x_i at its times t_i (i·h for a plan from t = 0). Between steps the rest position follows
a C² cubic spline through the x_i (leaving and arriving with the plan's first and last velocities), so
rest position and velocity are smooth at the control rate (a piecewise-linear rest would jerk the arm
every h seconds). The spline goes through the positions, not the plan's velocities: the model's forward
Euler step moves x_i with v_i over a whole step, so no smooth curve honours both (see
:mod:`comanip.simulation.person`). Before the plan's first time and after its last the rest holds the plan's first
and last points.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.interpolate import CubicSpline

from comanip.planning.plan import Plan


class RestTarget(NamedTuple):
    """Where the impedance controller's rest point is, and how it moves, at one instant."""

    position: np.ndarray
    """Rest position (3,), m, robot base frame."""
    velocity: np.ndarray | None
    """Rest velocity (3,), m/s; None: not given."""


class RestTrajectory:
    """A rest motion sampled on a fine time grid and looked up per control step.

    Args:
        position: rest positions (N, 3), m, at times time_offset + k·dt.
        velocity: rest velocities (N, 3), m/s, at the same times.
        time_offset: real time (s) of sample 0.
        dt: control period (s) of the grid.
    """

    def __init__(self, position, velocity, time_offset: float, dt: float):
        self.position, self.velocity = np.array(position, dtype=float), np.array(velocity, dtype=float)
        if self.position.ndim != 2 or self.position.shape != self.velocity.shape or len(self.position) == 0:
            raise ValueError(f"position and velocity must be (N, d) arrays of one shape, got "
                             f"{self.position.shape} and {self.velocity.shape}")
        self.time_offset, self.dt = float(time_offset), float(dt)

    @classmethod
    def from_plan(cls, plan: Plan, time_offset: float, dt: float, duration: float) -> "RestTrajectory":
        """A plan in task space (d = 3) as the rest motion: the plan at t - time_offset for real time t (s),
        sampled every dt (s) over duration (s) from time_offset on."""
        return cls._through(plan.t, plan.ee_mean, plan.ee_velocity[0], plan.ee_velocity[-1], time_offset, dt, duration)

    @classmethod
    def from_timed_reach(cls, reach, dt: float, duration: float) -> "RestTrajectory":
        """A point mass's reach played at a person's timing (a
        :class:`~comanip.estimation.model_reaches.reach_timing.TimedPlan` of a 3-D point mass, on the estimator's clock) as the
        rest motion, as :meth:`from_plan` plays a plan from time 0."""
        return cls._through(reach.t, reach.mean[:, :3], reach.mean[0, 3:6], reach.mean[-1, 3:6], 0.0, dt, duration)

    @classmethod
    def _through(cls, t, position, first_velocity, last_velocity, time_offset: float, dt: float, duration: float):
        """The C² spline through positions (K, d) m at times t (K,) s, leaving and arriving with the given
        velocities (d,) m/s, sampled every dt over duration from time_offset on (module docstring)."""
        spline = CubicSpline(t, position, bc_type=((1, first_velocity), (1, last_velocity)))
        tau = np.arange(int(np.ceil(duration / dt)) + 2) * dt
        inside = np.clip(tau, t[0], t[-1])
        velocity = np.where(((tau >= t[0]) & (tau <= t[-1]))[:, None], spline(inside, 1), 0.0)
        return cls(spline(inside), velocity, time_offset, dt)

    def positions(self, times) -> np.ndarray:
        """The rest positions (M, d), m, at real times (M,) s, held at the ends (as :meth:`__call__`)."""
        k = np.rint((np.asarray(times, dtype=float) - self.time_offset) / self.dt).astype(int)
        return self.position[np.clip(k, 0, len(self.position) - 1)]

    def __call__(self, t: float) -> RestTarget:
        """The rest position and velocity at real time t (s), held at the ends."""
        k = int(round((t - self.time_offset) / self.dt))
        k = min(max(k, 0), len(self.position) - 1)
        return RestTarget(self.position[k], self.velocity[k])
