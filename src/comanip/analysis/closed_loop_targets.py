"""The human-likeness targets on closed-loop executions: the person replans every step from what they see.

A plan is what the robot predicts; a person executes it with feedback: :func:`comanip.execution.
execute_receding_horizon` replans every step from the state, or, with the model's ``observation`` (or one
given here), from a Kalman estimate of it made from noisy, delayed observations. Each condition of the grid
runs ``n_trials`` executions from rest at the home position; the scored profile is their mean end-effector
velocity (docs/formulation.md §6 timing, the same shape measures as open loop), the hand is scored at the first step at or
after MT:

- hit rate, Monte Carlo: the share of executions with ||x − g|| ≤ w there;
- hit rate, "closed form": the ball probability of the Gaussian fitted to those hands (mean and covariance),
  a cross-check of the count (no closed form of the replanning loop exists);
- endpoint SD along and across the reach: of the executions (both the measured and the "predicted" columns).
"""

from __future__ import annotations

import time

import numpy as np

from comanip.analysis.ball_probability import ball_probability
from comanip.analysis.fitts import index_of_difficulty
from comanip.analysis.human_targets import TARGET_DISTANCES, TARGET_WIDTHS, ConditionTargets, HumanTargetsResult, score_rows
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_speed_fraction
from comanip.analysis.profile_shape import profile_shape
from comanip.analysis.reach_grid import ReachOutcome, home_start, unit_direction
from comanip.analysis.speed_profile import speed_metrics
from comanip.analysis.target_verdicts import HumanTargets
from comanip.arguments import as_count
from comanip.execution import execute_receding_horizon
from comanip.model import ReachingModel
from comanip.planning.planner import Planner


def measure_closed_loop_targets(model: ReachingModel, n_trials: int = 20, seed: int = 0, observation=None,
                                steps: int | None = None, targets: HumanTargets = HumanTargets(),
                                distances=TARGET_DISTANCES, widths=TARGET_WIDTHS, progress=None) -> HumanTargetsResult:
    """Score model's closed-loop executions on the grid distances × widths (m).

    Args:
        n_trials: executions per condition (the hit rate's resolution is 1/n_trials).
        seed: seed of the motor and sensory noise.
        observation: a :class:`comanip.execution.Observation`; None uses the model's (exact state without one).
        steps: steps executed per trial (default 1.5 H, so slow reaches settle and the end speed is seen).
        progress: progress(1) after each condition.
    """
    n_trials = as_count("n_trials", n_trials)
    began = time.perf_counter()
    planner, rng = Planner(model), np.random.default_rng(seed)
    steps = int(1.5 * model.H) if steps is None else as_count("steps", steps)
    start, x0 = home_start(model)
    along = unit_direction(model, None)
    rows, outcomes = [], []
    for distance in distances:
        for width in widths:
            goal = x0 + float(distance) * along
            runs = [execute_receding_horizon(planner, start, goal, width, steps=steps, rng=rng, observation=observation)
                    for _ in range(n_trials)]
            outcome, row = _condition(runs, float(distance), float(width), goal, along, targets)
            outcomes.append(outcome)
            rows.append(row)
            if progress:
                progress(1)
    return score_rows(f"{model.name} closed loop", rows, outcomes, targets, began)


def _condition(runs, distance: float, width: float, goal: np.ndarray, along: np.ndarray,
               targets: HumanTargets) -> tuple[ReachOutcome, ConditionTargets]:
    """The outcome and the target numbers of one condition's executions."""
    t = runs[0].t
    velocity = np.mean([run.ee_velocity for run in runs], axis=0)
    metrics = speed_metrics(t, np.linalg.norm(velocity, axis=1))
    mt = metrics.movement_time
    shape = profile_shape(t, velocity, along, targets.onset_time, targets.peak_floor)
    step = min(int(np.ceil(mt / (t[1] - t[0]) - 1e-9)), len(t) - 1) if np.isfinite(mt) else len(t) - 1
    hands = np.array([run.ee[step] for run in runs])
    offsets = hands - goal
    cov = np.atleast_2d(np.cov(offsets.T)) if len(runs) > 1 else np.zeros((len(goal), len(goal)))
    across = _across(along, cov)
    sd_along, sd_across = (float(np.std(offsets @ u, ddof=1)) if len(runs) > 1 else 0.0 for u in (along, across))
    success = all(run.failed_replans == 0 for run in runs)
    final = np.mean([run.ee[-1] for run in runs], axis=0)
    outcome = ReachOutcome(distance, width, t, velocity, metrics, success, float(np.linalg.norm(final - goal)), trials=len(runs))
    row = ConditionTargets(
        distance=distance, width=width, index_of_difficulty=float(index_of_difficulty(distance, width)),
        movement_time=mt, t_peak=metrics.t_peak, asymmetry=metrics.asymmetry, peak_speed=metrics.peak_speed,
        peak_speed_ratio=metrics.peak_speed * mt / distance, onset=shape.onset,
        onset_minimum_jerk=float(minimum_jerk_speed_fraction(targets.onset_time, mt)) if np.isfinite(mt) else float("nan"),
        peaks=shape.peaks, reversal=shape.reversal, end_speed=shape.end_speed, endpoint_time=float(t[step]),
        hit_rate_closed_form=ball_probability(offsets.mean(axis=0), cov, width),
        hit_rate_monte_carlo=float(np.mean(np.linalg.norm(offsets, axis=1) <= width)),
        sd_along=sd_along, sd_across=sd_across, sd_along_predicted=sd_along, sd_across_predicted=sd_across,
        samples=len(runs), success=success)
    return outcome, row


def _across(along: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """The unit direction perpendicular to ``along`` (d,) with the largest spread under cov (d, d)."""
    projector = np.eye(len(along)) - np.outer(along, along)
    _, vectors = np.linalg.eigh(projector @ cov @ projector + 1e-30 * projector)
    return vectors[:, -1]
