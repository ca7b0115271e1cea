"""Robot→person authority handover at the predicted transition point (paper VI-B, docs/formulation.md §8).

The robot leads a reach planned with the motor-control model (the Cartesian preset): the planned mean hand
path is the rest position x_r(t) (m) of a Cartesian impedance controller whose translational stiffness K(t)
(N/m, equal on every axis) holds the hand to it, F = K(t) (x_r(t) - x) (N). The transition model predicts
at what distance T (m) from the goal a person would switch from the fast initial sub-movement to the
corrective one; the first time the planned hand comes within T of the goal, t_h, the robot hands the
authority over: K falls from K_0 (400 N/m) to 0 along a raised-cosine ramp of duration T_r,

    K(t) = K_0                                  t ≤ t_h
    K(t) = K_0 (1 + cos(π (t - t_h) / T_r)) / 2  t_h < t < t_h + T_r
    K(t) = 0                                    t ≥ t_h + T_r,

and the person finishes the reach. T_r = 0 is the paper's instantaneous switch.

Force-step bound. Sampled every Δt (s), the ramp changes K by at most K_0 sin(π Δt / (2 T_r)) ≤
K_0 π Δt / (2 T_r) per sample, so for a hand held e (m) off its rest position the stiffness part of the
commanded force changes by at most K_0 π e Δt / (2 T_r) per sample; the rest of the force's change,
K (e_{k+1} - e_k), is the ordinary spring following the motion. Default T_r = 0.2 s at 1 kHz: ≤ 3.14 N/m
(0.79 % of K_0) per sample, 0.031 N at e = 1 cm, where an instantaneous switch drops 4 N at once. 0.2 s
is about one human reaction time, so the release completes as one felt event while the remaining
corrective movement (several tenths of a second) is still ahead.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from comanip.arguments import as_optional_positive, as_positive
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.multicomponent.transition_model import TransitionModel
from comanip.planning.plan import Plan

LEADING_STIFFNESS = 400.0
"""Translational stiffness while the robot leads (N/m), paper VI-B."""

DEFAULT_RAMP_TIME = 0.2
"""Default duration (s) of the stiffness ramp to 0; see the module docstring for the bound it gives."""


@dataclass
class HandoverSchedule:
    """What an impedance controller consumes, sample by sample (T samples, d task axes), and where the
    authority passes. Every array is in SI units: s, m, m/s, N/m."""

    t: np.ndarray
    """Sample times (T,), s, from the start of the plan."""
    rest_position: np.ndarray
    """Impedance rest position x_r (T, d), m: a C² cubic spline through the planned mean hand positions,
    held at the last one after the plan ends."""
    rest_velocity: np.ndarray
    """dx_r/dt (T, d), m/s."""
    stiffness: np.ndarray
    """Translational stiffness K (T,), N/m, the same on every axis (rotational stiffness stays high)."""
    goal: np.ndarray
    """Goal (d,), m."""
    width: float
    """Goal width w, m."""
    goal_distance: float
    """D = distance of the planned start from the goal, m."""
    transition_distance: float
    """Predicted distance from the goal of the transition, T, m (model mean)."""
    transition_distance_std: float
    """Model std of T, m."""
    transition_time: float
    """t_h: when the stiffness starts to fall, s."""
    transition_position: np.ndarray
    """x_r(t_h) (d,), m."""
    ramp_time: float
    """T_r, s (0: instantaneous switch)."""
    leading_stiffness: float
    """K_0, N/m."""
    status: str
    """'within_plan' (the plan comes within T of the goal at t_h), 'at_start' (T ≥ D: the person leads from
    the start) or 'at_end' (the plan never comes within T: handover when the plan ends)."""
    rate: float | None = None
    """Controller rate (Hz) of a resampled schedule; None: the plan's own time grid plus t_h and t_h + T_r."""

    @property
    def distance_to_goal(self) -> np.ndarray:
        """||x_r - goal|| (T,), m."""
        return np.linalg.norm(self.rest_position - self.goal, axis=1)

    @property
    def rest_speed(self) -> np.ndarray:
        """||dx_r/dt|| (T,), m/s."""
        return np.linalg.norm(self.rest_velocity, axis=1)

    @property
    def stiffness_step_bound(self) -> float:
        """Largest change of K between consecutive samples that the ramp law allows, N/m (see module docstring)."""
        return stiffness_step_bound(self.leading_stiffness, self.ramp_time, float(np.max(np.diff(self.t))))

    def force_step_bound(self, deviation: float) -> float:
        """Largest per-sample change (N) of the stiffness part of the force on a hand deviation (m) off x_r."""
        return self.stiffness_step_bound * as_positive("deviation", deviation, "m")

    def summary(self) -> dict:
        """The handover in numbers (JSON-ready), without the sample arrays."""
        return {"goal_m": self.goal.tolist(), "width_m": self.width, "goal_distance_m": self.goal_distance,
                "transition_distance_m": self.transition_distance,
                "transition_distance_std_m": self.transition_distance_std, "transition_time_s": self.transition_time,
                "transition_position_m": self.transition_position.tolist(), "status": self.status,
                "ramp_time_s": self.ramp_time, "leading_stiffness_N_per_m": self.leading_stiffness,
                "released_at_s": self.transition_time + self.ramp_time, "samples": len(self.t), "rate_hz": self.rate,
                "stiffness_step_bound_N_per_m": self.stiffness_step_bound,
                "force_step_bound_N_at_1cm": self.force_step_bound(0.01)}

    def to_dict(self) -> dict:
        out = self.summary()
        out.update(t_s=self.t.tolist(), rest_position_m=self.rest_position.tolist(),
                   rest_velocity_m_per_s=self.rest_velocity.tolist(), stiffness_N_per_m=self.stiffness.tolist())
        return out

    def save_json(self, path: str | Path) -> Path:
        """The summary and every sample array, as one JSON object."""
        Path(path).write_text(json.dumps(self.to_dict(), indent=1))
        return Path(path)

    def save_csv(self, path: str | Path) -> Path:
        """One row per sample: t, rest position, rest velocity, stiffness, distance to goal."""
        axes = "xyz"[: self.goal.size]      # task space: planar (2) or Cartesian (3)
        with open(path, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(["t_s"] + [f"rest_{a}_m" for a in axes] + [f"rest_v_{a}_m_per_s" for a in axes]
                            + ["stiffness_N_per_m", "distance_to_goal_m"])
            for row in zip(self.t, self.rest_position, self.rest_velocity, self.stiffness, self.distance_to_goal):
                writer.writerow([f"{row[0]:.6f}", *(f"{v:.6g}" for v in row[1]), *(f"{v:.6g}" for v in row[2]),
                                 f"{row[3]:.6g}", f"{row[4]:.6g}"])
        return Path(path)


def stiffness_profile(t, transition_time: float, ramp_time: float, leading_stiffness: float = LEADING_STIFFNESS) -> np.ndarray:
    """K(t) (N/m) at times t (s): K_0 until transition_time, raised-cosine ramp to 0 over ramp_time, then 0."""
    t = np.asarray(t, dtype=float)
    if ramp_time == 0:
        return np.where(t <= transition_time, leading_stiffness, 0.0)
    s = np.clip((t - transition_time) / ramp_time, 0.0, 1.0)
    return leading_stiffness * 0.5 * (1.0 + np.cos(np.pi * s))


def stiffness_step_bound(leading_stiffness: float, ramp_time: float, sample_time: float) -> float:
    """K_0 sin(π Δt / (2 T_r)) (N/m): the ramp's largest change between samples Δt (s) apart; K_0 when T_r = 0."""
    if ramp_time == 0:
        return leading_stiffness
    return leading_stiffness * math.sin(min(math.pi * sample_time / (2 * ramp_time), math.pi / 2))


def check_schedule_arguments(ramp_time, leading_stiffness, rate) -> tuple[float, float, float | None]:
    """(ramp_time ≥ 0 s, leading_stiffness > 0 N/m, rate > 0 Hz or None) as floats, else ValueError."""
    if isinstance(ramp_time, bool) or not isinstance(ramp_time, (int, float)) or not math.isfinite(ramp_time) or ramp_time < 0:
        raise ValueError(f"ramp_time must be a finite number ≥ 0 (s), got {ramp_time!r}")
    return (float(ramp_time), as_positive("leading_stiffness", leading_stiffness, "N/m"),
            as_optional_positive("rate", rate, "Hz"))


def plan_handover(plan: Plan | OnlineEstimate, model: TransitionModel, ramp_time: float = DEFAULT_RAMP_TIME,
                  leading_stiffness: float = LEADING_STIFFNESS, rate: float | None = None) -> HandoverSchedule:
    """When and where the robot hands the reach over, and the schedule its impedance controller follows.

    Args:
        plan: the robot's plan (e.g. ``Planner(presets.cartesian()).solve(...)``), its mean hand path the rest
            position, or an online estimate (:class:`~comanip.estimation.OnlineEstimate`), its path of the hand
            from the latest observation on; their goal and width are the reach's.
        model: the transition model; queried at the plan's goal distance D (m) and width w (m).
        ramp_time: T_r (s) ≥ 0 of the stiffness ramp to 0 (0: instantaneous switch).
        leading_stiffness: K_0 (N/m) > 0 while the robot leads.
        rate: controller rate (Hz) to resample at (e.g. 1000); None keeps the plan's grid (plus t_h, t_h + T_r).
    """
    if isinstance(plan, OnlineEstimate):
        times, positions, velocities = plan.path.t, plan.path.position, plan.path.velocity
    elif isinstance(plan, Plan):
        times, positions, velocities = plan.t, plan.ee_mean, plan.ee_velocity
    else:
        raise ValueError(f"plan must be a comanip.Plan (from Planner.solve) or an online estimate, got {type(plan).__name__}")
    if not isinstance(model, TransitionModel) or not model.is_fitted:
        raise ValueError("model must be a fitted comanip.TransitionModel (e.g. comanip.TransitionModel())")
    ramp_time, leading_stiffness, rate = check_schedule_arguments(ramp_time, leading_stiffness, rate)
    if not np.all(np.isfinite(positions)):
        raise ValueError(f"plan holds a non-finite hand path (status '{plan.status}'); replan before handing over")

    goal = np.asarray(plan.goal, dtype=float)
    path = CubicSpline(times, positions, bc_type=((1, velocities[0]), (1, velocities[-1])))
    goal_distance = plan.reach_distance
    mean, std = model.predict(goal_distance, plan.width)
    transition_time, status = _first_time_within(path, goal, mean, times[0], times[-1])
    end = max(times[-1], transition_time + ramp_time)
    if rate is None:
        t = np.union1d(times, [transition_time, transition_time + ramp_time])
    else:
        t = np.arange(times[0], end + 0.5 / rate, 1.0 / rate)
    held = t > times[-1]
    position = path(np.minimum(t, times[-1]))
    velocity = np.where(held[:, None], 0.0, path(np.minimum(t, times[-1]), 1))
    return HandoverSchedule(
        t=t, rest_position=position, rest_velocity=velocity,
        stiffness=stiffness_profile(t, transition_time, ramp_time, leading_stiffness),
        goal=goal, width=float(plan.width), goal_distance=goal_distance, transition_distance=float(mean),
        transition_distance_std=float(std), transition_time=float(transition_time),
        transition_position=np.asarray(path(min(transition_time, times[-1]))), ramp_time=ramp_time,
        leading_stiffness=leading_stiffness, status=status, rate=rate)


def _first_time_within(path: CubicSpline, goal: np.ndarray, distance: float, t0: float, t1: float) -> tuple[float, str]:
    """First time (s) in [t0, t1] at which ||path(t) - goal|| ≤ distance (m), and the status word."""
    def gap(t):
        return float(np.linalg.norm(path(t) - goal)) - distance

    if gap(t0) <= 0:
        return t0, "at_start"
    # scan at 1 ms, then refine the first bracketed crossing to machine precision
    times = np.linspace(t0, t1, max(2, int(np.ceil((t1 - t0) / 1e-3)) + 1))
    gaps = np.linalg.norm(path(times) - goal, axis=1) - distance
    inside = np.flatnonzero(gaps <= 0)
    if inside.size == 0:
        return t1, "at_end"
    k = int(inside[0])
    return brentq(gap, times[k - 1], times[k], xtol=1e-9), "within_plan"
