"""The result of a planning solve, in the shape of scipy's OptimizeResult: status first, then the plan."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field, replace
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from comanip.optim import CONVERGED

if TYPE_CHECKING:  # the planner makes it; a plan only carries it
    from comanip.planning.goal_sensitivity import GoalSensitivity


class PlanStatus(StrEnum):
    """How a plan ended when the solver's outcome (:class:`comanip.optim.Status`) does not say it. A ``str``, like
    :class:`comanip.optim.Status`."""

    GOAL_NOT_REACHED = "goal_not_reached"
    """The solver converged but the plan's mean end effector ends farther than the goal width from the goal."""
    UNREACHABLE = "unreachable"
    """The goal is out of the arm's reach; nothing was solved."""


@dataclass
class Plan:
    """A planned reach and how the solve went.

    Shapes: H steps, n degrees of freedom, d task dimensions. Units: s, m, m/s, N·m (or N for point masses).
    """

    success: bool
    """True when the solver converged (to its tolerance or an acceptable level) to a finite plan whose mean
    end effector ends within the goal width w of the goal."""
    status: StrEnum
    """How the solve ended: a :class:`comanip.optim.Status` or a :class:`PlanStatus` (a plan made by a layer above
    carries that layer's status, e.g. a goal estimate's :class:`comanip.estimation.estimate_status.EstimateStatus`): 'solved',
    'solved_acceptable' (converged and reaching), 'goal_not_reached' (converged, but the mean end
    effector ends farther than w from the goal: e.g. a goal too far for the horizon, or not worth the effort;
    ``extras['solver_status']`` keeps the solver's word), 'max_iterations', 'max_wall_time', 'unreachable'
    (goal out of the arm's reach), 'constraints_violated' (joint limits could not be met) or 'failed'.
    The README's status table says the same."""
    message: str
    """What the solver said, in words."""
    objective: float
    """docs/formulation.md §4 objective J at the returned torques (lower is better)."""
    solve_time: float
    """Wall time of the solve (s), initial guesses included."""
    iterations: int
    """Solver iterations (summed over starts)."""
    t: np.ndarray
    """Times (H+1,), s."""
    mean: np.ndarray
    """Mean state mu_i = [q; qdot; activation forces] (H+1, nx): nx = 2n, plus n per activation stage."""
    cov: np.ndarray
    """State covariance Sigma_i (H+1, nx, nx)."""
    torque: np.ndarray
    """Planned command tau_i (H, n); tau_i acts from t_i to t_{i+1}."""
    ee_mean: np.ndarray
    """End-effector mean mu_x,i (H+1, d), m."""
    ee_cov: np.ndarray
    """End-effector covariance Sigma_x,i (H+1, d, d), m²."""
    ee_velocity: np.ndarray
    """End-effector mean velocity J(mu_q) mu_qdot (H+1, d), m/s."""
    start: np.ndarray
    """Start state s_0 (nx,)."""
    goal: np.ndarray
    """Goal position (d,), m."""
    width: float
    """Goal width w (m)."""
    model_name: str = ""
    extras: dict = field(default_factory=dict)
    """Application-specific results (e.g. an estimated goal)."""
    goal_sensitivity: GoalSensitivity | None = field(default=None, repr=False, compare=False)
    """How the torques move with the goal, for a converged point-mass plan of the planner that solved it
    (:class:`~comanip.planning.goal_sensitivity.GoalSensitivity`; None otherwise, and in another process): a warm
    solve from this plan to a moved goal starts from its first-order prediction."""

    @property
    def reach_distance(self) -> float:
        """D (m): from where the reach starts to the goal, |x(t_0) - g|."""
        return float(np.linalg.norm(self.ee_mean[0] - np.asarray(self.goal, dtype=float)))

    @property
    def ee_speed(self) -> np.ndarray:
        """Speed of the mean end effector ||d mu_x/dt|| (H+1,), m/s."""
        return np.linalg.norm(self.ee_velocity, axis=1)

    @property
    def ee_std(self) -> np.ndarray:
        """Per-axis standard deviation of the end effector (H+1, d), m."""
        return np.sqrt(np.maximum(np.diagonal(self.ee_cov, axis1=1, axis2=2), 0.0))

    @property
    def final_error(self) -> float:
        """Distance of the final mean end effector from the goal (m)."""
        return float(np.linalg.norm(self.ee_mean[-1] - self.goal))

    @property
    def reaches_goal(self) -> bool:
        """True when the final mean end effector is within the goal width of the goal (final_error ≤ w)."""
        return self.final_error <= self.width

    @property
    def converged(self) -> bool:
        """True when the solver converged, whether or not the plan reaches the goal (see ``success``)."""
        return self.status in CONVERGED or self.status == PlanStatus.GOAL_NOT_REACHED

    def to_dict(self) -> dict:
        """JSON-ready dictionary (arrays as nested lists)."""
        out = {}
        for name in self.__dataclass_fields__:
            if name == "goal_sensitivity":  # the solver's state, not a result
                continue
            value = getattr(self, name)
            out[name] = value.tolist() if isinstance(value, np.ndarray) else value
        out["extras"] = {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in self.extras.items()}
        return out

    def save_json(self, path: str | Path) -> Path:
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    def save_csv(self, path: str | Path) -> Path:
        """One row per step: t, q, qdot, the activation stages (a{stage}_{k}, models with them), x, x velocity,
        x std, tau (empty on the last row)."""
        path = Path(path)
        n, d = self.torque.shape[1], self.ee_mean.shape[1]
        axes = "xyz"[:d] if d <= 3 else [str(k) for k in range(d)]
        stages = range(1, (self.mean.shape[1] - 2 * n) // n + 1)
        header = (["t_s"] + [f"q{k}" for k in range(n)] + [f"qdot{k}" for k in range(n)]
                  + [f"a{j}_{k}" for j in stages for k in range(n)]
                  + [f"x_{a}_m" for a in axes] + [f"v_{a}_m_per_s" for a in axes] + [f"std_{a}_m" for a in axes]
                  + [f"tau{k}" for k in range(n)])
        with open(path, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(header)
            for i, t in enumerate(self.t):
                tau = self.torque[i].tolist() if i < len(self.torque) else [""] * n
                writer.writerow([t, *self.mean[i], *self.ee_mean[i], *self.ee_velocity[i], *self.ee_std[i], *tau])
        return path

    def summary(self) -> str:
        return (f"{self.status} ({'success' if self.success else 'no success'}) objective {self.objective:.4g}, "
                f"{self.iterations} iterations in {1e3 * self.solve_time:.1f} ms; final error {1e3 * self.final_error:.1f} mm")


def with_reach_check(plan: Plan) -> Plan:
    """The plan, or, when the solver converged but the mean end effector ends farther than the goal width from
    the goal, a copy with status 'goal_not_reached', success False and the solver's status in
    ``extras['solver_status']``."""
    if plan.status not in CONVERGED or plan.reaches_goal:
        return plan
    message = (f"the plan ends {plan.final_error:.4g} m from the goal, beyond the goal width {plan.width:g} m "
               f"(solver: {plan.status}, {plan.message})")
    return replace(plan, success=False, status=PlanStatus.GOAL_NOT_REACHED, message=message,
                   extras={**plan.extras, "solver_status": plan.status})
