"""A validation run: every analysis of the paper's Section IV-D on one model, the calibration study, the
human-likeness targets and the Franka section (Section V-B), written as CSV files, ``report.json``
(every number) and ``report.md`` (the same, as tables). The run computes what its figures show
(:class:`~comanip.validation.figure_data.ValidationFigureData`) and leaves the drawing to the caller's ``draw``
step (``comanip validate`` passes :func:`comanip.plots.validation_figures.draw_validation_figures`).

A point-mass model gets the Section IV-D analyses, the human-likeness targets beside a reference preset
(``settings.human_targets``, ``settings.human_reference``) and, unless ``settings.franka`` is False, the Franka
section planned with the built-in ``franka`` preset. An arm model (the Panda) gets the Franka section alone:
the point-mass grids (a dozen cold solves, hundreds of closed-loop replans) are not what its section shows.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Callable

import numpy as np

from comanip import presets
from comanip.analysis import (
    Configuration,
    endpoint_dispersion,
    fit_fitts,
    index_of_difficulty,
    measure_grid,
    minimum_jerk_asymmetry,
    open_loop_grid,
    phase_curves,
    run_calibration,
    study_configurations,
)
from comanip.analysis.calibration import HUMAN_MT_RANGE, TREND_TOLERANCE
from comanip.analysis.reach_grid import ReachOutcome, home_start, unit_direction
from comanip.model import ReachingModel
from comanip.planning.planner import Planner
from comanip.progress import progress_bar
from comanip.validation.arm_section import run_arm_section
from comanip.validation.figure_data import PointMassFigureData, ValidationFigureData
from comanip.validation.human_section import run_human_section
from comanip.validation.markdown import report_markdown
from comanip.validation.run_settings import ValidationSettings


def run_validation(model: ReachingModel, out: str | Path, settings: ValidationSettings | None = None,
                   progress: bool = True,
                   draw: Callable[[ValidationFigureData, Path], list[Path]] | None = None) -> dict:
    """Run every analysis on model, write the reports and CSV files into out; returns the report dictionary.

    ``draw(figure_data, out)``, when given, draws the figures into out (e.g.
    :func:`comanip.plots.validation_figures.draw_validation_figures`) and returns their paths, which the
    report lists under "figures"; without it no figure is drawn and the list is empty.

    Raises ValueError, before any work, for an arm model with ``settings.franka`` False (nothing to run) and
    for a human-likeness reference that is not a point-mass model.
    """
    settings = settings or ValidationSettings()
    point_mass = model.body.is_linear
    if not point_mass and not settings.franka:
        raise ValueError(f"franka is False (--no-franka) but the model {model.name!r} is an arm ({model.body.name}), whose "
                         "validation is the Franka section alone: nothing to run (the other analyses need a point-mass "
                         "preset such as planar)")
    reference = presets.load(settings.human_reference) if point_mass and settings.human_targets else None
    if reference is not None and not reference.body.is_linear:
        raise ValueError(f"the human-likeness reference {settings.human_reference!r} must be a point-mass model, "
                         f"got an arm ({reference.body.name})")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    began = time.perf_counter()
    report = {"model": model.config(), "settings": settings.to_dict()}
    figure_data = ValidationFigureData()
    if point_mass:
        sections, figure_data.point_mass, grid = _point_mass_sections(model, settings, progress)
        report |= sections
        if reference is not None:
            report["human_targets"], figure_data.human_targets = run_human_section(model, reference, grid, settings, progress)
    if settings.franka:
        arm = model if not point_mass else presets.load("franka")
        report["franka"], figure_data.arm = run_arm_section(arm, out, settings, progress)
    figures = [] if draw is None else draw(figure_data, out)
    report |= {"figures": [f.name for f in figures], "wall_time_s": time.perf_counter() - began}
    (out / "report.json").write_text(json.dumps(_plain(report), indent=1))
    (out / "report.md").write_text(report_markdown(report))
    return report


def _point_mass_sections(model: ReachingModel, settings: ValidationSettings,
                         progress: bool) -> tuple[dict, PointMassFigureData, list[ReachOutcome]]:
    """The Section IV-D analyses and the calibration study: report entries, what their figures show, and the
    open-loop outcomes (with plans) of the distances × widths grid."""
    planner = Planner(model)
    rng = np.random.default_rng(settings.seed)
    n_grid = len(settings.distances) * len(settings.widths)
    n_phase = len(settings.phase_distances) + len(settings.phase_initial_velocities)
    with progress_bar("validation", n_grid + len(settings.dispersion_widths) + n_phase, "reach", progress) as bar:
        grid = open_loop_grid(planner, settings.distances, settings.widths, progress=bar.update)
        start, x0 = home_start(model)
        dispersion_goal = x0 + settings.dispersion_distance * unit_direction(model)
        dispersions = []
        for width in settings.dispersion_widths:
            plan = planner.solve(start, dispersion_goal, width)
            dispersions.append((plan, endpoint_dispersion(model, plan, settings.dispersion_samples, rng)))
            bar.update(1)
        by_distance = phase_curves(planner, settings.phase_distances, [0.0], settings.phase_width)
        bar.update(len(by_distance))
        by_velocity = phase_curves(planner, [settings.profile_distance], settings.phase_initial_velocities, settings.phase_width)
        bar.update(len(by_velocity))
    calibration = run_calibration(model, study_configurations(settings.quick), settings.distances, settings.widths,
                                  n_trials=settings.calibration_trials, seed=settings.seed, workers=settings.workers,
                                  progress=progress)
    calibration_rows = [result.summary() for result in calibration]

    measured = measure_grid(grid, Configuration(model.name), model.goal_covariance)
    grid, fits, grid_row = measured.outcomes, [measured.fitts, measured.shannon], measured.summary()
    ids = index_of_difficulty(np.array([o.distance for o in grid]), np.array([o.width for o in grid]))
    figure_data = PointMassFigureData(
        model.name, grid, fits, settings.profile_distance, settings.profile_width, [d for _, d in dispersions],
        dispersion_goal, by_distance, by_velocity, calibration_rows, (float(ids.min()), float(ids.max())),
        len(settings.distances), len(settings.widths))

    report = {
        "fitts_grid": _fitts_grid_report(grid_row, fits),
        "dispersion": {
            "goal_m": dispersion_goal.tolist(),
            "widths": [d.summary() | {"plan_success": plan.success} for plan, d in dispersions],
        },
        "phase": {"by_distance": [c.summary() for c in by_distance], "by_initial_velocity": [c.summary() for c in by_velocity]},
        "calibration": {
            "configurations": calibration_rows,
            "both": [row["configuration"] for row in calibration_rows if row["both"]],
            "fitts_law": [row["configuration"] for row in calibration_rows if row["fitts_law"]],
            "early_peak": [row["configuration"] for row in calibration_rows if row["early_peak"]],
            # Under W = w I a scale-invariant model's MT is a function of D/sqrt(w), not of D/w; even an MT exactly
            # linear in log2(2D/sqrt(w)) would fit the Fitts and Shannon forms on this grid only this well:
            **{f"cov_reading_{form}_r2_if_log_linear": _r2_if_log_linear_in_d_over_sqrt_w(grid, form) for form in ("fitts", "shannon")},
        },
    }
    return report, figure_data, grid


def _fitts_grid_report(grid_row: dict, fits) -> dict:
    """The report entry of the distances × widths grid: its conditions with their indices of difficulty, the Fitts
    and Shannon fits, the trends and the movement times against the human range."""
    return {
        "conditions": [c | {"id_fitts_bits": float(index_of_difficulty(c["distance_m"], c["width_m"], "fitts")),
                            "id_shannon_bits": float(index_of_difficulty(c["distance_m"], c["width_m"], "shannon"))}
                       for c in grid_row["conditions"]],
        "fits": {fit.form: fit.to_dict() for fit in fits},
        "width_trend": grid_row["width_trend"],
        "distance_trend": grid_row["distance_trend"],
        "trend_tolerance_s": TREND_TOLERANCE,
        "mt_in_human_range": grid_row["mt_in_human_range"],
        "human_mt_range_s": list(HUMAN_MT_RANGE),
        "all_solves_converged": grid_row["all_solves_converged"],
        "asymmetry_min": grid_row["asymmetry_min"], "asymmetry_median": grid_row["asymmetry_median"],
        "asymmetry_max": grid_row["asymmetry_max"],
        "minimum_jerk_asymmetry": minimum_jerk_asymmetry(),
    }


def _r2_if_log_linear_in_d_over_sqrt_w(grid, form: str) -> float:
    """R² of the Fitts fit (form) to an MT exactly linear in log2(2D/sqrt(w)) over the grid's conditions."""
    D = np.array([o.distance for o in grid])
    w = np.array([o.width for o in grid])
    return fit_fitts(D, w, np.log2(2 * D / np.sqrt(w)), form).r2


def _plain(value):
    """JSON-safe copy: NumPy scalars to Python, NaN and inf to None."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (np.floating, float)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value
