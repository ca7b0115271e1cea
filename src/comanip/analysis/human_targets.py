"""Score a model against the human-likeness targets (thresholds and verdicts in
:mod:`comanip.analysis.target_verdicts`).

Each condition of the grid D × w is an open-loop plan from rest at the body's home position to a goal D
along the first task axis (:func:`comanip.analysis.open_loop_grid`), measured on its mean:

- timing (docs/formulation.md §6, :func:`comanip.analysis.speed_metrics`): t_peak, MT, t_peak/MT, peak speed / (D/MT);
- shape (:func:`comanip.analysis.profile_shape`): onset, peaks, reversal, end speed;
- the hand at the first step at or after MT (the last step when the reach never settles): the hit rate
  P(||x − g|| ≤ w) in closed form from the plan's predicted mean and covariance there
  (:func:`comanip.analysis.ball_probability`, exact for a Gaussian, which an open-loop point-mass plan
  is) and by open-loop Monte Carlo of the noisy dynamics (:func:`comanip.analysis.endpoint_dispersion`,
  the same step), with the endpoint SD along and across the reach from both.

w is the goal radius and ID = log2(2D/w) (bits).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.stats import linregress

from comanip.analysis.ball_probability import ball_probability
from comanip.analysis.open_loop_dispersion import endpoint_dispersion
from comanip.analysis.fitts import FittsFit, fit_fitts, index_of_difficulty
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_speed_fraction
from comanip.analysis.profile_shape import profile_shape
from comanip.analysis.reach_grid import ReachOutcome, open_loop_grid
from comanip.analysis.target_verdicts import ConditionTargets, HumanTargets, TargetVerdict, target_verdicts
from comanip.model import ReachingModel
from comanip.planning.planner import Planner

TARGET_DISTANCES = (0.15, 0.3, 0.45)
"""The grid of the targets: distances D (m)."""
TARGET_WIDTHS = (0.005, 0.01, 0.02, 0.04)
"""... and goal radii w (m)."""


@dataclass(frozen=True)
class HumanTargetsResult:
    """One model scored over the grid: rows ordered distances outer, widths inner."""

    model_name: str
    rows: list[ConditionTargets]
    outcomes: list[ReachOutcome]
    """The scored outcomes (open-loop plans, or closed-loop executions), in the order of rows."""
    fitts: FittsFit
    """MT = a + b·log2(2D/w) over the rows with a finite MT."""
    asymmetry_slope: float
    """Least-squares slope of t_peak/MT against ID (1/bit; NaN with fewer than 3 finite rows)."""
    verdicts: list[TargetVerdict]
    wall_time: float
    """Time to plan (when planned here) and score the grid (s)."""

    @property
    def passed(self) -> int:
        """Targets passed (of len(verdicts))."""
        return sum(v.passed for v in self.verdicts)

    def to_dict(self) -> dict:
        return {"model": self.model_name, "fitts": self.fitts.to_dict(), "asymmetry_slope_per_bit": self.asymmetry_slope,
                "passed": self.passed, "targets": len(self.verdicts), "wall_time_s": self.wall_time,
                "verdicts": [v.to_dict() for v in self.verdicts], "conditions": [r.to_dict() for r in self.rows]}


def measure_human_targets(model: ReachingModel, outcomes: list[ReachOutcome] | None = None, n_samples: int = 2000,
                          seed: int = 0, targets: HumanTargets = HumanTargets(), distances=TARGET_DISTANCES,
                          widths=TARGET_WIDTHS, progress=None) -> HumanTargetsResult:
    """Score model on a grid. outcomes: open-loop outcomes already planned for model (each with its plan),
    e.g. by a validation run; when None, planned here over distances × widths (m). n_samples: Monte Carlo
    executions per condition (seeded by seed). progress(1) after each reach planned and each scored."""
    began = time.perf_counter()
    if outcomes is None:
        outcomes = open_loop_grid(Planner(model), distances, widths, progress=progress)
    if any(o.plan is None for o in outcomes):
        raise ValueError("every outcome needs its open-loop plan (closed-loop outcomes cannot be scored)")
    outcomes = sorted(outcomes, key=lambda o: (o.distance, o.width))
    rng = np.random.default_rng(seed)
    rows = []
    for outcome in outcomes:
        rows.append(condition_targets(model, outcome, n_samples, rng, targets))
        if progress:
            progress(1)
    return score_rows(model.name, rows, outcomes, targets, began)


def score_rows(model_name: str, rows: list[ConditionTargets], outcomes: list[ReachOutcome], targets: HumanTargets,
               began: float) -> HumanTargetsResult:
    """The grid's Fitts fit, t_peak/MT slope and verdicts from its per-condition rows; began: perf_counter at the start."""
    D, w, mt, ratio = (np.array([getattr(r, k) for r in rows], dtype=float)
                       for k in ("distance", "width", "movement_time", "asymmetry"))
    fit = fit_fitts(D, w, mt, "fitts")
    ids, finite = index_of_difficulty(D, w), np.isfinite(ratio)
    slope = (float(linregress(ids[finite], ratio[finite]).slope)
             if finite.sum() >= 3 and np.ptp(ids[finite]) > 0 else float("nan"))
    return HumanTargetsResult(model_name, rows, outcomes, fit, slope, target_verdicts(rows, fit, slope, targets),
                              time.perf_counter() - began)


def condition_targets(model: ReachingModel, outcome: ReachOutcome, n_samples: int, rng: np.random.Generator,
                      targets: HumanTargets = HumanTargets()) -> ConditionTargets:
    """The numbers of one open-loop outcome (with its plan) of model; n_samples Monte Carlo executions."""
    plan, metrics = outcome.plan, outcome.metrics
    shape = profile_shape(plan.t, plan.ee_velocity, plan.goal - plan.ee_mean[0], targets.onset_time, targets.peak_floor)
    spread = endpoint_dispersion(model, plan, n_samples, rng)
    step = spread.step
    mt = metrics.movement_time
    return ConditionTargets(
        distance=outcome.distance, width=outcome.width,
        index_of_difficulty=float(index_of_difficulty(outcome.distance, outcome.width)),
        movement_time=mt, t_peak=metrics.t_peak, asymmetry=metrics.asymmetry, peak_speed=metrics.peak_speed,
        peak_speed_ratio=metrics.peak_speed * mt / outcome.distance,
        onset=shape.onset,
        onset_minimum_jerk=float(minimum_jerk_speed_fraction(targets.onset_time, mt)) if np.isfinite(mt) else float("nan"),
        peaks=shape.peaks, reversal=shape.reversal, end_speed=shape.end_speed, endpoint_time=spread.time,
        hit_rate_closed_form=ball_probability(plan.ee_mean[step] - plan.goal, plan.ee_cov[step], plan.width),
        hit_rate_monte_carlo=spread.hit_rate,
        sd_along=spread.along_std, sd_across=spread.across_std,
        sd_along_predicted=spread.predicted_along_std, sd_across_predicted=spread.predicted_across_std,
        samples=n_samples, success=outcome.success)
