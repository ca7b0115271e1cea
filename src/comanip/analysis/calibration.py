"""The calibration study: which configuration of the model gets Fitts' law and an early velocity peak?

docs/formulation.md §3 records that a faithful re-implementation got Fitts' law (W = w² I) or an early peak (W = w I),
never both. This study measures, for each configuration of the model's own family (ReachingModel fields
and the execution mode; nothing is tuned by hand), over a grid of distances D × widths w:

- t_peak/MT per condition (docs/formulation.md §6), and how many conditions have it below 0.5 (the paper's claim);
- the Fitts and Shannon fits MT = a + b·ID (R², slope);
- the trends: wider goal → no slower at fixed D, farther goal → no faster at fixed w;
- whether every movement time lies in a human range and every reach finished (speed fell below 5 %).

A configuration *gets Fitts' law* when every reach finished, max(R² Fitts, R² Shannon) ≥ 0.9, both trends
hold in every neighbouring pair, and every MT lies in 0.2–1.5 s. It *gets an early peak* when
t_peak/MT < 0.5 in every condition. Open-loop configurations are measured on the plan's mean; closed-loop
ones on the mean executed velocity over trials, replanning every step from the noisy state.

Conditions run in a process pool (one planner per configuration and worker, built once).
"""

from __future__ import annotations

import os
from multiprocessing import get_context
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from itertools import product

import numpy as np
from scipy.stats import linregress

from comanip.caching.process_caches import PROCESS_CACHES
from comanip.analysis.fitts import FittsFit, fit_fitts, trend_fraction
from comanip.analysis.reach_grid import ReachOutcome, closed_loop_grid, open_loop_grid
from comanip.arguments import as_count
from comanip.model import ReachingModel
from comanip.objectives.reward import goal_covariance
from comanip.planning.planner_cache import PlannerCache
from comanip.progress import progress_bar

FITTS_R2_MIN = 0.9
"""Fitts' law holds when the better of the two fits has at least this R²."""
HUMAN_MT_RANGE = (0.2, 1.5)
"""Human movement times (s), roughly."""
EARLY_PEAK_MAX = 0.5
"""The paper's early-peak claim: t_peak/MT below this in every condition."""
TREND_TOLERANCE = 1e-3
"""Movement times closer than this (s) count as equal in the width and distance trends."""


@dataclass(frozen=True)
class Configuration:
    """One member of the model family: field changes to the base model, and how the reach is executed."""

    name: str
    """Label in tables and figures."""
    changes: dict = field(default_factory=dict)
    """ReachingModel field overrides (e.g. {"goal_covariance": "cov", "H": 60})."""
    closed_loop: bool = False
    """False: measure the open-loop plan; True: execute with replanning every step and sampled noise."""

    def model(self, base: ReachingModel) -> ReachingModel:
        """The base model with this configuration's changes (checked by ReachingModel)."""
        return base.replace(**self.changes, name=f"{base.name}[{self.name}]")

    @property
    def mode(self) -> str:
        return "closed loop" if self.closed_loop else "open loop"


def study_configurations(quick: bool = False) -> list[Configuration]:
    """The configurations measured by ``comanip validate``.

    Full: every combination of the W reading (std, cov), noise form (isotropic, per_channel, rank_one),
    discounting (exponential, hyperbolic) and horizon (H = 30, 60) in open loop (24); the default with
    kappa 1e-3 and 3e-2 and with gamma 1.0 (the ends of the plausible range; 3); and closed loop for both
    W readings at both horizons (isotropic noise, exponential discounting; 4). Quick: the default and one
    change at a time in open loop (6), and the default in closed loop.
    """
    choices = {"goal_covariance": ("std", "cov"), "noise": ("isotropic", "per_channel", "rank_one"),
               "discount": ("exponential", "hyperbolic"), "H": (30, 60)}
    default = {key: values[0] for key, values in choices.items()}
    if quick:
        variants = [default] + [default | {key: values[1]} for key, values in choices.items()] + [default | {"noise": "rank_one"}]
        closed = [default]
    else:
        variants = ([dict(zip(choices, combo)) for combo in product(*choices.values())]
                    + [default | {"kappa": 1e-3}, default | {"kappa": 3e-2}, default | {"gamma": 1.0}])
        closed = [default | {"goal_covariance": W, "H": H} for W, H in product(("std", "cov"), (30, 60))]
    return ([Configuration(_label(v), v) for v in variants]
            + [Configuration(_label(v) + " closed", v, closed_loop=True) for v in closed])


def _label(changes: dict) -> str:
    short = {"isotropic": "iso", "per_channel": "chan", "rank_one": "rank1", "exponential": "exp", "hyperbolic": "hyp"}
    main = ("goal_covariance", "noise", "discount")
    others = "".join(f" {key}={value:g}" for key, value in changes.items() if key not in main + ("H",))
    return "W=" + " ".join(short.get(changes[k], changes[k]) for k in main) + f" H={changes['H']}" + others


@dataclass
class CalibrationResult:
    """One configuration measured over the grid (outcomes ordered distances outer, widths inner, both ascending)."""

    configuration: Configuration
    distances: np.ndarray
    """Distances D (nD,), m, ascending."""
    widths: np.ndarray
    """Widths w (nW,), m, ascending."""
    outcomes: list[ReachOutcome]
    fitts: FittsFit
    shannon: FittsFit
    goal_covariance: str = "std"
    """The W reading the configuration planned with ('std' W = w² I or 'cov' W = w I)."""

    @property
    def effective_ids(self) -> np.ndarray:
        """Effective index of difficulty log2(2D / sqrt(W)) (nD, nW), bits: the Fitts ID with the goal's
        standard deviation in place of w (equal to the Fitts ID under the 'std' reading)."""
        goal_std = np.sqrt([goal_covariance(w, 1, self.goal_covariance)[0, 0] for w in self.widths])
        return np.log2(2 * self.distances[:, None] / goal_std[None, :])

    @property
    def movement_times(self) -> np.ndarray:
        """MT (nD, nW), s (NaN where the reach did not finish)."""
        return np.array([o.metrics.movement_time for o in self.outcomes]).reshape(len(self.distances), len(self.widths))

    @property
    def asymmetries(self) -> np.ndarray:
        """t_peak/MT (nD, nW)."""
        return np.array([o.metrics.asymmetry for o in self.outcomes]).reshape(len(self.distances), len(self.widths))

    def summary(self) -> dict:
        """The table row: every number the report shows for this configuration."""
        mt, ratio = self.movement_times, self.asymmetries
        settled = bool(np.all(np.isfinite(mt)))
        width_trend = trend_fraction(mt, increasing=False, tolerance=TREND_TOLERANCE)
        distance_trend = trend_fraction(mt.T, increasing=True, tolerance=TREND_TOLERANCE)
        mt_in_range = settled and bool(np.all((mt >= HUMAN_MT_RANGE[0]) & (mt <= HUMAN_MT_RANGE[1])))
        best_r2 = np.nanmax([self.fitts.r2, self.shannon.r2, -np.inf])
        fitts_law = settled and best_r2 >= FITTS_R2_MIN and width_trend == 1 and distance_trend == 1 and mt_in_range
        early_peak = settled and bool(np.all(ratio < EARLY_PEAK_MAX))
        ids = self.effective_ids
        finite = np.isfinite(ratio)
        trend = linregress(ids[finite], ratio[finite]) if finite.sum() >= 3 and np.ptp(ids[finite]) > 0 else None
        return {
            "configuration": self.configuration.name, "mode": self.configuration.mode,
            "changes": dict(self.configuration.changes), "goal_covariance": self.goal_covariance,
            "all_solves_converged": all(o.success for o in self.outcomes), "all_reaches_finished": settled,
            "asymmetry_min": _nan_stat(np.nanmin, ratio), "asymmetry_median": _nan_stat(np.nanmedian, ratio),
            "asymmetry_max": _nan_stat(np.nanmax, ratio),
            "early_fraction": float(np.mean(ratio < EARLY_PEAK_MAX)),
            "mt_min_s": _nan_stat(np.nanmin, mt), "mt_max_s": _nan_stat(np.nanmax, mt),
            "fitts_r2": self.fitts.r2, "fitts_slope_s_per_bit": self.fitts.b, "fitts_intercept_s": self.fitts.a,
            "shannon_r2": self.shannon.r2, "shannon_slope_s_per_bit": self.shannon.b, "shannon_intercept_s": self.shannon.a,
            "width_trend": width_trend, "distance_trend": distance_trend, "mt_in_human_range": mt_in_range,
            "fitts_law": bool(fitts_law), "early_peak": early_peak, "both": bool(fitts_law and early_peak),
            # t_peak/MT against the effective ID: its slope (per bit) and where the line crosses the 0.5 claim
            "asymmetry_slope_per_bit": float(trend.slope) if trend else float("nan"),
            "effective_id_at_half_bits": (float((EARLY_PEAK_MAX - trend.intercept) / trend.slope)
                                          if trend and trend.slope != 0 else float("nan")),
            "conditions": [o.summary() | {"effective_id_bits": float(x)} for o, x in zip(self.outcomes, ids.ravel())],
        }


def _nan_stat(stat, values) -> float:
    return float(stat(values)) if np.any(np.isfinite(values)) else float("nan")


def measure_grid(outcomes: list[ReachOutcome], configuration: Configuration, goal_covariance_form: str = "std") -> CalibrationResult:
    """A :class:`CalibrationResult` from the outcomes of a full distances × widths grid (any order), planned
    with the W reading goal_covariance_form."""
    outcomes = sorted(outcomes, key=lambda o: (o.distance, o.width))
    distances = np.unique([o.distance for o in outcomes])
    widths = np.unique([o.width for o in outcomes])
    if len(outcomes) != len(distances) * len(widths):
        raise ValueError(f"outcomes must cover a full grid: {len(outcomes)} outcomes for {len(distances)} distances × {len(widths)} widths")
    D = np.array([o.distance for o in outcomes])
    w = np.array([o.width for o in outcomes])
    mt = np.array([o.metrics.movement_time for o in outcomes])
    return CalibrationResult(configuration, distances, widths, outcomes,
                             fit_fitts(D, w, mt, "fitts"), fit_fitts(D, w, mt, "shannon"), goal_covariance_form)


def run_calibration(base: ReachingModel, configurations: list[Configuration], distances, widths, n_trials: int = 8,
                    seed: int = 0, workers: int | None = None, progress: bool = True) -> list[CalibrationResult]:
    """Measure every configuration over distances × widths (m); one result per configuration, in order.

    Closed-loop configurations average n_trials executions of 2H steps per condition, with motor noise drawn
    from a generator seeded by (seed, configuration index, condition index), so results do not depend on
    the scheduling. workers: processes (default: the CPU count; 1 runs in this process).
    """
    as_count("n_trials", n_trials)
    distances, widths = np.sort(np.asarray(distances, float)), np.sort(np.asarray(widths, float))
    tasks = [(base.config(), c, float(D), float(w), n_trials, (seed, i, j))
             for i, c in enumerate(configurations) for j, (D, w) in enumerate(product(distances, widths))]
    workers = (os.cpu_count() or 1) if workers is None else workers
    as_count("workers", workers, 1, "processes")
    bar = progress_bar("calibration", len(tasks), "reach", progress)
    results: dict[int, list[ReachOutcome]] = {i: [] for i in range(len(configurations))}
    if workers == 1:
        planners = PlannerCache(size=1)
        for task in tasks:
            results[task[-1][1]].append(_run_condition(planners, *task))
            bar.update(1)
    else:
        with ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn")) as pool:
            futures = {pool.submit(_run_condition_in_worker, *task): task[-1][1] for task in tasks}
            for future in as_completed(futures):
                results[futures[future]].append(future.result())
                bar.update(1)
    bar.close()
    return [measure_grid(results[i], c, c.model(base).goal_covariance) for i, c in enumerate(configurations)]


def _worker_planners() -> PlannerCache:
    """A pool worker's planner cache (its process's, :data:`comanip.caching.process_caches.PROCESS_CACHES`). It keeps
    one planner: conditions are submitted configuration by configuration, so a worker reuses it for a run of
    conditions, and one bounds the memory a worker holds."""
    return PROCESS_CACHES.get("calibration planners", lambda: PlannerCache(size=1))


def _run_condition_in_worker(*task) -> ReachOutcome:
    return _run_condition(_worker_planners(), *task)


def _run_condition(planners: PlannerCache, base_config: dict, configuration: Configuration, distance: float,
                   width: float, n_trials: int, seed_key: tuple[int, int, int]) -> ReachOutcome:
    planner = planners.planner(configuration.model(ReachingModel.from_config(base_config)))
    if configuration.closed_loop:
        rng = np.random.default_rng(np.random.SeedSequence(list(seed_key)))
        return closed_loop_grid(planner, [distance], [width], n_trials, rng)[0]
    outcome = open_loop_grid(planner, [distance], [width])[0]
    outcome.plan = None  # keep what crosses the process boundary small; the figures use their own plans
    return outcome
