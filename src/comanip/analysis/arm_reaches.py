"""Reaches of an arm (the 7-DOF Panda, paper Section V-B) from its home pose to goals around it, measured
the way a robotics user reads a plan: did the solve succeed and how fast, where does the hand end, how does
its speed rise and fall, and how much of each joint limit does the plan use.

Every reach starts at rest at the body's home position (the Panda's ready pose) and aims at the home
end-effector position plus an offset (m). The first goal is solved cold (multi-start); each later one is
warm-started from the plan before it, as a robot following a person's goals would. Timing is docs/formulation.md §6's
(:func:`comanip.analysis.speed_metrics` on the hand speed ||J(mu_q) mu_qdot||).

Limit usage, per joint, as a fraction of the limit (1 = at the limit), over the mean of steps 1..H:
position |q - q_mid| / (½ (q_max - q_min)) with q_mid the middle of the range; velocity |qdot| / qdot_max;
torque |tau| / tau_max over the H commands.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from comanip.analysis.reach_grid import home_start
from comanip.analysis.speed_profile import SpeedMetrics, speed_metrics
from comanip.arguments import as_matrix, as_optional_positive
from comanip.planning.path_limits import LIMIT_TOLERANCE, PathLimits
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner

LIMIT_KINDS = ("position", "velocity", "torque")
"""The kinds of joint limit, in the order the reports list them."""


@dataclass(frozen=True)
class LimitUsage:
    """How much of its joint limits one plan uses: per joint (n,), fractions of the limit (1 = at the limit)."""

    position: np.ndarray
    velocity: np.ndarray
    torque: np.ndarray
    within_limits: bool
    """The mean path keeps the position and velocity limits within the planner's tolerance
    (:data:`comanip.planning.path_limits.LIMIT_TOLERANCE`) and every torque is within its bound."""

    def summary(self) -> dict:
        """Largest usage of each kind and its joint (1-based, as on the robot), the per-joint lists, the verdict."""
        out = {}
        for kind in LIMIT_KINDS:
            usage = getattr(self, kind)
            out[f"{kind}_usage_max"] = float(np.max(usage))
            out[f"{kind}_usage_joint"] = int(np.argmax(usage)) + 1
            out[f"{kind}_usage_per_joint"] = usage.tolist()
        return out | {"within_limits": self.within_limits}


def joint_limit_usage(model, plan: Plan) -> LimitUsage:
    """Limit usage (see the module docstring) of plan, a plan of model's arm."""
    body, n = model.body, model.n
    q, qdot = plan.mean[1:, :n], plan.mean[1:, n:2 * n]
    middle, half_range = (body.q_max + body.q_min) / 2, (body.q_max - body.q_min) / 2
    position = np.max(np.abs(q - middle), axis=0) / half_range
    velocity = np.max(np.abs(qdot), axis=0) / body.qdot_max
    torque = np.max(np.abs(plan.torque), axis=0) / body.tau_max
    within = (PathLimits.of(model).violation(plan.mean) <= LIMIT_TOLERANCE
              and bool(np.all(np.abs(plan.torque) <= body.tau_max * (1 + 1e-9))))
    return LimitUsage(position, velocity, torque, within)


def _velocity_usage_after(model, plan: Plan, time: float) -> float:
    """Largest |qdot| / qdot_max over the joints and the steps after time (s); NaN for a NaN time or no step."""
    after = plan.t > time  # False everywhere for a NaN time
    if not after.any():
        return float("nan")
    return float(np.max(np.abs(plan.mean[after, model.n:2 * model.n]) / model.body.qdot_max))


AT_VELOCITY_LIMIT = 0.95
"""A joint counts as at its velocity limit at |qdot| ≥ this fraction of qdot_max."""


@dataclass(frozen=True)
class SettlingMotion:
    """How an arm moves once its hand has stopped (after MT, docs/formulation.md §6), and how it ends."""

    final_joint_speed: float
    """Largest |qdot_H| over the joints at the end of the plan, rad/s."""
    time_at_velocity_limit: float
    """Time (s) after MT during which some joint runs at ≥ AT_VELOCITY_LIMIT of its speed limit (steps × h);
    NaN when the hand never settles."""


def settling_motion(model, plan: Plan) -> SettlingMotion:
    """:class:`SettlingMotion` of plan, a plan of model's arm (a body with joint velocity limits)."""
    n, qdot_max = model.n, model.body.qdot_max
    movement_time = speed_metrics(plan.t, plan.ee_speed).movement_time
    qdot = np.abs(plan.mean[:, n:2 * n])
    at_limit = np.any(qdot >= AT_VELOCITY_LIMIT * qdot_max, axis=1) & (plan.t > movement_time)
    return SettlingMotion(float(np.max(qdot[-1])),
                          float(np.sum(at_limit) * model.h) if np.isfinite(movement_time) else float("nan"))


@dataclass
class ArmReach:
    """One planned reach of an arm from its home pose; T = H+1 steps."""

    offset: np.ndarray
    """Goal minus the home end-effector position (3,), m."""
    plan: Plan
    warm_started: bool
    """Solved from the previous goal's plan (False: a cold multi-start solve)."""
    metrics: SpeedMetrics
    """docs/formulation.md §6 timing of the hand speed."""
    limits: LimitUsage
    velocity_usage_after_mt: float
    """Largest |qdot| / qdot_max of any joint after MT: how fast the arm still moves (in its null space) once
    the hand has stopped; NaN when the hand never settles."""

    @property
    def label(self) -> str:
        """The offset in words, e.g. '+0.20 m x' or '(+0.10, +0.15, -0.10) m'."""
        nonzero = np.flatnonzero(self.offset)
        if len(nonzero) == 1:
            k = int(nonzero[0])
            return f"{self.offset[k]:+.2f} m {'xyz'[k]}"
        return "(" + ", ".join(f"{v:+.2f}" for v in self.offset) + ") m"

    @property
    def within_width(self) -> bool:
        """The mean hand ends within the goal width of the goal."""
        return self.plan.final_error <= self.plan.width

    def summary(self) -> dict:
        """Plain numbers of this reach (no arrays), for reports; times in s, distances in m, speeds in m/s."""
        plan = self.plan
        return {"goal_label": self.label, "offset_m": self.offset.tolist(), "goal_m": plan.goal.tolist(),
                "distance_m": float(np.linalg.norm(self.offset)), "width_m": plan.width,
                "success": plan.success, "status": plan.status, "message": plan.message,
                "warm_started": self.warm_started, "solve_time_s": plan.solve_time, "iterations": plan.iterations,
                "final_error_m": plan.final_error, "within_width": self.within_width,
                **self.metrics.to_dict(), "final_speed": float(plan.ee_speed[-1]), **self.limits.summary(),
                "velocity_usage_after_mt": self.velocity_usage_after_mt}


def arm_reaches(planner: Planner, offsets, width: float | None = None, max_wall_time: float | None = None,
                progress: Callable[[int], object] | None = None) -> list[ArmReach]:
    """Plan a reach from rest at the home pose to home end effector + each offset (k, d) in m, in order.

    width: goal width (m), the model's when None. max_wall_time: budget per solve (s); a solve that runs out
    returns its best plan with status 'max_wall_time'. progress(1) is called after each reach.
    """
    model = planner.model
    if model.body.joint_limits is None:
        raise ValueError(f"planner must plan for an arm with joint limits (e.g. comanip.presets.franka()), "
                         f"got a {model.body.name!r} body without limits")
    if len(offsets) == 0:
        raise ValueError(f"offsets must hold at least one goal offset of shape ({model.d},), m, got none")
    offsets = as_matrix("offsets", offsets, (len(offsets), model.d), "goal offsets from the home end-effector position, m")
    width = as_optional_positive("width", width, "m")
    max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")
    start, x0 = home_start(model)
    reaches, plan = [], None
    for offset in offsets:
        warm = plan is not None
        plan = planner.solve(start, x0 + offset, width, warm_start=plan,
                             max_wall_time=max_wall_time)
        metrics = speed_metrics(plan.t, plan.ee_speed)
        reaches.append(ArmReach(offset, plan, warm, metrics, joint_limit_usage(model, plan),
                                _velocity_usage_after(model, plan, metrics.movement_time)))
        if progress:
            progress(1)
    return reaches


def summarise_reaches(reaches: list[ArmReach]) -> dict:
    """Numbers over all reaches: successes, goals within width, cold and median warm solve time (s), the
    largest usage of each limit kind and the largest joint speed usage after MT."""
    warm = [r.plan.solve_time for r in reaches if r.warm_started]
    cold = [r.plan.solve_time for r in reaches if not r.warm_started]
    after_mt = [r.velocity_usage_after_mt for r in reaches if np.isfinite(r.velocity_usage_after_mt)]
    return {"reaches": len(reaches), "successes": sum(r.plan.success for r in reaches),
            "within_width": sum(r.within_width for r in reaches),
            "within_limits": sum(r.limits.within_limits for r in reaches),
            "cold_solve_time_s": cold[0] if cold else None,
            "warm_solve_time_median_s": float(np.median(warm)) if warm else None,
            "warm_solve_time_max_s": max(warm) if warm else None,
            **{f"{kind}_usage_max": float(max(np.max(getattr(r.limits, kind)) for r in reaches)) for kind in LIMIT_KINDS},
            "velocity_usage_after_mt_max": max(after_mt) if after_mt else None}
