"""Phase portraits of planned reaches over goal distances and initial velocities (paper Fig. 5, Section V-A).

Each curve is one open-loop plan from the home position; position and velocity are the mean hand's
components along the reach direction, position measured from the start. A start with initial velocity v0
(m/s along the reach direction) has joint velocity J(q0)^+ v0 u.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.analysis.reach_grid import home_start, unit_direction
from comanip.analysis.speed_profile import SpeedMetrics, speed_metrics
from comanip.planning.planner import Planner


@dataclass
class PhaseCurve:
    """One planned reach seen along its direction. T = H+1 steps."""

    distance: float
    """Start-to-goal distance (m)."""
    initial_velocity: float
    """Hand velocity at the start along the reach direction (m/s)."""
    width: float
    """Goal width (m)."""
    t: np.ndarray
    """Times (T,), s."""
    position: np.ndarray
    """Mean hand position along the direction, from the start (T,), m."""
    velocity: np.ndarray
    """Mean hand velocity along the direction (T,), m/s."""
    metrics: SpeedMetrics
    """docs/formulation.md §6 timing of the plan's speed."""
    success: bool
    final_error: float
    """Distance of the final mean hand from the goal (m)."""

    def summary(self) -> dict:
        return {"distance_m": self.distance, "initial_velocity_m_per_s": self.initial_velocity, "width_m": self.width,
                "peak_velocity_m_per_s": float(np.max(self.velocity)), **self.metrics.to_dict(),
                "success": self.success, "final_error_m": self.final_error}


def phase_curves(planner: Planner, distances, initial_velocities, width: float, direction=None) -> list[PhaseCurve]:
    """One plan per (distance, initial velocity) pair (distances outer), all to goals of the given width (m)."""
    model = planner.model
    start, x0 = home_start(model)
    u = unit_direction(model, direction)
    J = np.asarray(model.body.kinematics_function(start[: model.n])[1])
    curves = []
    for distance in distances:
        for v0 in initial_velocities:
            s0 = start.copy()
            s0[model.n : 2 * model.n] = np.linalg.lstsq(J, float(v0) * u, rcond=None)[0]
            plan = planner.solve(s0, x0 + float(distance) * u, width)
            curves.append(PhaseCurve(float(distance), float(v0), float(width), plan.t, (plan.ee_mean - x0) @ u,
                                     plan.ee_velocity @ u, speed_metrics(plan.t, plan.ee_speed), plan.success,
                                     plan.final_error))
    return curves
