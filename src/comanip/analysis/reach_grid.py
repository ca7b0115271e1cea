"""Reaches over a grid of goal distances and widths, planned open loop or executed in closed loop.

Every reach starts at rest at the body's home position and aims at a goal ``distance`` metres away along
``direction`` (default: the first task axis, x). An open-loop outcome is the plan's mean; a closed-loop
outcome is the mean over trials of the executed end-effector velocity (replanning every step from the
noisy state, or from the person's estimate of it under an observation model,
:func:`comanip.execution.execute_receding_horizon`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from comanip.analysis.speed_profile import SpeedMetrics, speed_metrics
from comanip.arguments import as_count
from comanip.execution import Observation, execute_receding_horizon
from comanip.model import ReachingModel
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner


@dataclass
class ReachOutcome:
    """One condition of a grid. Shapes: T samples, d task dimensions."""

    distance: float
    """Start-to-goal distance D (m)."""
    width: float
    """Goal width w (m)."""
    t: np.ndarray
    """Times (T,), s."""
    velocity: np.ndarray
    """Mean end-effector velocity (T, d), m/s: the plan's, or the mean over executed trials."""
    metrics: SpeedMetrics
    """docs/formulation.md §6 timing of ||velocity||."""
    success: bool
    """Every solve (and, in closed loop, every replan) converged."""
    final_error: float
    """Distance from the goal of the mean final end-effector position (m)."""
    trials: int = 0
    """Executed trials averaged (0: an open-loop plan)."""
    plan: Plan | None = None
    """The open-loop plan (None in closed loop)."""

    @property
    def speed(self) -> np.ndarray:
        """||velocity|| (T,), m/s."""
        return np.linalg.norm(self.velocity, axis=1)

    def summary(self) -> dict:
        """Plain numbers of this outcome (no arrays), for reports."""
        return {"distance_m": self.distance, "width_m": self.width, **self.metrics.to_dict(),
                "success": self.success, "final_error_m": self.final_error, "trials": self.trials}


def home_start(model: ReachingModel) -> tuple[np.ndarray, np.ndarray]:
    """Start state at rest at the body's home position (nx,; activation stages at zero force), and its
    end-effector position (d,), m."""
    q0 = model.body.home_position
    x0 = np.asarray(model.body.kinematics_function(q0)[0]).ravel()
    return model.full_state(np.concatenate([q0, np.zeros(model.n)])), x0


def unit_direction(model: ReachingModel, direction=None) -> np.ndarray:
    """Unit vector (d,) of the reach direction; the first task axis when None."""
    u = np.eye(model.d)[0] if direction is None else np.asarray(direction, dtype=float)
    if u.shape != (model.d,) or not np.all(np.isfinite(u)) or np.linalg.norm(u) == 0:
        raise ValueError(f"direction must be a non-zero finite vector of shape ({model.d},), got {direction!r}")
    return u / np.linalg.norm(u)


def open_loop_grid(planner: Planner, distances, widths, direction=None,
                   progress: Callable[[int], object] | None = None) -> list[ReachOutcome]:
    """Plans (cold, multi-start) for every (distance, width) pair, distances outer; progress(1) after each."""

    def reach(start, goal, distance, width):
        plan = planner.solve(start, goal, width)
        return ReachOutcome(distance, width, plan.t, plan.ee_velocity, speed_metrics(plan.t, plan.ee_speed),
                            plan.success, plan.final_error, plan=plan)

    return _over_grid(planner.model, distances, widths, direction, progress, reach)


def closed_loop_grid(planner: Planner, distances, widths, n_trials: int, rng: np.random.Generator,
                     steps: int | None = None, direction=None,
                     progress: Callable[[int], object] | None = None,
                     observation: Observation | None = None) -> list[ReachOutcome]:
    """Closed-loop executions (n_trials per condition, steps each; default 2H so slow reaches finish), replanned
    from the actual state (observation None) or from the estimate made with the observation's noise and delay."""
    as_count("n_trials", n_trials)
    steps = 2 * planner.model.H if steps is None else steps

    def reach(start, goal, distance, width):
        runs = [execute_receding_horizon(planner, start, goal, width, steps=steps, rng=rng, observation=observation)
                for _ in range(n_trials)]
        velocity = np.mean([run.ee_velocity for run in runs], axis=0)
        final = np.mean([run.ee[-1] for run in runs], axis=0)
        return ReachOutcome(distance, width, runs[0].t, velocity, speed_metrics(runs[0].t, np.linalg.norm(velocity, axis=1)),
                            all(run.failed_replans == 0 for run in runs), float(np.linalg.norm(final - goal)),
                            trials=n_trials)

    return _over_grid(planner.model, distances, widths, direction, progress, reach)


def _over_grid(model, distances, widths, direction, progress, reach) -> list[ReachOutcome]:
    """reach(start (nx,), goal (d,), distance, width) for every pair, distances outer; progress(1) after each."""
    start, x0 = home_start(model)
    u = unit_direction(model, direction)
    outcomes = []
    for distance in distances:
        for width in widths:
            outcomes.append(reach(start, x0 + float(distance) * u, float(distance), float(width)))
            if progress:
                progress(1)
    return outcomes
