"""How far the fitted model's predictions are from the recordings, per trial and per condition.

Position error: RMS over a trial's scored samples (after the first, within the horizon) of the distance between the recorded hand
and the predicted mean (m). Movement time (MT, s): :func:`comanip.analysis.speed_metrics` (first time
after the speed peak below 5 % of the peak) of the predicted mean speed and of the recorded speed: per
trial from its own samples, per condition from the mean of its trials on the plan's time grid (averaging
removes most of the noise a single trial's differentiated speed carries).
"""

from __future__ import annotations

import numpy as np

from comanip.analysis.speed_profile import speed_metrics
from comanip.fitting.conditions import Condition
from comanip.fitting.likelihood import interpolate, predicted_mean, scored_samples
from comanip.recordings.trial_files import Trial
from comanip.planning.plan import Plan


def movement_time(t: np.ndarray, speed: np.ndarray) -> float:
    """MT (s) of a speed profile at uniform times; NaN when it never settles or has < 3 samples."""
    return speed_metrics(t, speed).movement_time if len(t) >= 3 else np.nan


def recorded_speed(t: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Speed of recorded positions (K, d), m, at times t (K,), s, resampled at the median sample step:
    (uniform times (K',), speed (K',) m/s) by central differences."""
    dt = float(np.median(np.diff(t)))
    grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1)
    return grid, np.linalg.norm(np.gradient(interpolate(t, position, grid), dt, axis=0), axis=1)


def trial_residuals(trials: list[Trial], conditions: list[Condition], plans: list[Plan]) -> list[dict]:
    """Per trial: name, condition index, samples (all, used), RMS position error (m), MT recorded and predicted (s)."""
    rows = []
    for c, (condition, plan) in enumerate(zip(conditions, plans)):
        mt_predicted = movement_time(plan.t, plan.ee_speed)
        for k in condition.trials:
            trial = trials[k]
            keep = scored_samples(plan, trial)
            error = trial.position[keep] - predicted_mean(plan, trial, trial.start - condition.start)
            rows.append({"trial": trial.name, "condition": c, "samples": len(trial.t), "samples_used": int(keep.sum()),
                         "rms_error_m": float(np.sqrt(np.mean(np.sum(error**2, axis=1)))) if keep.any() else np.nan,
                         "mt_recorded_s": movement_time(*recorded_speed(trial.t, trial.position)),
                         "mt_predicted_s": mt_predicted})
    return rows


def condition_curves(trials: list[Trial], condition: Condition, plan: Plan) -> dict:
    """Mean recorded and predicted curves of a condition on the plan's grid (for the figure and the MT).

    Keys: t (T,) s, recorded_mean (T', d) m and recorded_speed (T',) m/s on the first T' steps (those every
    trial covers), predicted_mean (T, d), predicted_std (T, d) m, predicted_speed (T,) m/s.
    """
    members = [trials[k] for k in condition.trials]
    first, last = max(trial.t[0] for trial in members), min(trial.t[-1] for trial in members)
    covered = (plan.t >= first - 1e-12) & (plan.t <= last + 1e-12)
    t = plan.t[covered]
    mean = np.mean([interpolate(trial.t, trial.position - (trial.start - condition.start), t) for trial in members], axis=0)
    speed = np.linalg.norm(np.gradient(mean, plan.t[1] - plan.t[0], axis=0), axis=1) if len(t) >= 2 else np.zeros(len(t))
    return {"t": plan.t, "recorded_t": t, "recorded_mean": mean, "recorded_speed": speed,
            "predicted_mean": plan.ee_mean, "predicted_std": plan.ee_std, "predicted_speed": plan.ee_speed}


def condition_residuals(trial_rows: list[dict], conditions: list[Condition], plans: list[Plan], curves: list[dict]) -> list[dict]:
    """Per condition: start, goal, width, trials, plan status, RMS position error (m), MT of the mean recorded
    trajectory and of the plan (s) and their relative difference."""
    rows = []
    for c, (condition, plan, curve) in enumerate(zip(conditions, plans, curves)):
        members = [row for row in trial_rows if row["condition"] == c]
        squared = sum(row["rms_error_m"] ** 2 * row["samples_used"] for row in members if row["samples_used"])
        used = sum(row["samples_used"] for row in members)
        mt_recorded = movement_time(curve["recorded_t"], curve["recorded_speed"])
        mt_predicted = movement_time(plan.t, plan.ee_speed)
        rows.append({"condition": c, "start": condition.start.tolist(), "goal": condition.goal.tolist(),
                     "width": condition.width, "trials": len(members), "plan_status": plan.status,
                     "plan_success": plan.success, "rms_error_m": float(np.sqrt(squared / used)) if used else np.nan,
                     "mt_recorded_s": mt_recorded, "mt_predicted_s": mt_predicted,
                     "mt_relative_error": (mt_predicted - mt_recorded) / mt_recorded})
    return rows
