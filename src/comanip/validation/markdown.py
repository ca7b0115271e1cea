"""``report.md``: the validation report dictionary of :func:`comanip.validation.run.run_validation` as tables.

The human-likeness section's verdict table (:func:`verdict_table`) is also what
``studies/which_model_options_make_reaching_human_like/make_calibration_table.py`` writes into
docs/results/calibration.md."""

from __future__ import annotations

import math

from comanip.analysis.arm_reaches import LIMIT_KINDS
from comanip.analysis.calibration import EARLY_PEAK_MAX, FITTS_R2_MIN
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_asymmetry
from comanip.validation.paper_comparison import paper_comparison


def report_markdown(report: dict) -> str:
    """Markdown with every number of the report: one section per analysis (the point-mass analyses and the
    calibration table when the report has them, then the Franka section when it has one), then the figures."""
    model, settings = report["model"], report["settings"]
    lines = [f"# comanip validation report: {model['name']}", "",
             f"Model: {_model_line(model)}. Run: {'quick' if settings['quick'] else 'full'}, seed {settings['seed']}, "
             f"{_num(report['wall_time_s'], 1)} s.", ""]
    comparison = paper_comparison(report)
    if comparison:
        lines += ["## The paper's claims and this model", "",
                  "What the paper's Section IV-D shows, and what this model gives on the grid below.", "",
                  _table(["the paper", "where", "this model"], [[r["claim"], r["paper"], r["model"]] for r in comparison]), ""]
    if "fitts_grid" in report:
        lines += _point_mass_sections(report)
    if "human_targets" in report:
        lines += human_targets_markdown(report["human_targets"])
    if "franka" in report:
        lines += _franka_section(report["franka"], report["model"])
    if report["figures"]:
        lines += ["Figures: " + ", ".join(f"`{f}`" for f in report["figures"]), ""]
    return "\n".join(lines)


def _model_line(model: dict) -> str:
    return (f"H = {model['H']}, h = {model['h']} s, gamma = {model['gamma']}, nu = {model['nu']}, kappa = {model['kappa']}, "
            f"noise {model['noise']}, W reading {model['goal_covariance']}, {model['discount']} discounting")


def _point_mass_sections(report: dict) -> list[str]:
    settings, grid = report["settings"], report["fitts_grid"]
    return ["## Velocity profiles and asymmetry (paper Fig. 3, top; `velocity_profiles.png`)", "",
            "Open-loop plans from rest. MT: first time after the peak with speed below 5 % of the peak (docs/formulation.md §6). "
            f"A minimum-jerk reach has t_peak/MT = {_num(grid['minimum_jerk_asymmetry'], 3)} under this definition.", "",
            _table(["D (m)", "w (m)", "ID Fitts", "ID Shannon", "t_peak (s)", "MT (s)", "t_peak/MT", "min-jerk t_peak/MT",
                    "peak speed (m/s)", "final error (mm)", "converged"],
                   [[c["distance_m"], c["width_m"], _num(c["id_fitts_bits"], 2), _num(c["id_shannon_bits"], 2),
                     _num(c["t_peak"], 3), _num(c["movement_time"], 3), _num(c["asymmetry"], 3),
                     _num(grid["minimum_jerk_asymmetry"], 3), _num(c["peak_speed"], 3), _num(1e3 * c["final_error_m"], 2),
                     c["success"]] for c in grid["conditions"]]), "",
            "## Fitts' law (paper Fig. 3, bottom; `fitts.png`)", "",
            _table(["form", "a (s)", "b (s/bit)", "R²", "points"],
                   [[f["form"], _num(f["a"], 4), _num(f["b"], 4), _num(f["r2"], 4), f["n_points"]] for f in grid["fits"].values()]),
            "",
            f"- wider goal → no slower at fixed D (pairs within {grid['trend_tolerance_s']} s count as equal): "
            f"{_num(100 * grid['width_trend'], 0)} % of neighbouring pairs",
            f"- farther goal → no faster at fixed w: {_num(100 * grid['distance_trend'], 0)} % of neighbouring pairs",
            f"- every MT in {grid['human_mt_range_s'][0]}–{grid['human_mt_range_s'][1]} s: {grid['mt_in_human_range']}",
            f"- every solve converged: {grid['all_solves_converged']}", "",
            "## Endpoint dispersion (paper Fig. 4; `dispersion.png`)", "",
            f"Open-loop Monte Carlo of the planned torques to the goal {report['dispersion']['goal_m']} m; the hand at "
            "the first step at or after MT, split along and across the movement; 'predicted' is the plan's closed-form "
            "J Σ_qq Jᵀ at that step.", "",
            _table(["w (m)", "samples", "t (s)", "along std (mm)", "predicted (mm)", "across std (mm)", "predicted (mm)",
                    "Gaussian fit mean (mm)", "Gaussian fit std (mm)", "hit rate"],
                   [[d["width"], d["samples"], _num(d["time"], 3), _num(1e3 * d["along_std"], 3),
                     _num(1e3 * d["predicted_along_std"], 3), _num(1e3 * d["across_std"], 3),
                     _num(1e3 * d["predicted_across_std"], 3), _num(1e3 * d["across_fit_mean"], 3),
                     _num(1e3 * d["across_fit_std"], 3), _num(d["hit_rate"], 3)] for d in report["dispersion"]["widths"]]),
            "", "## Phase plots (paper Fig. 5; `phase.png`)", "",
            _table(["D (m)", "v0 (m/s)", "peak velocity (m/s)", "t_peak (s)", "MT (s)", "final error (mm)", "converged"],
                   [[c["distance_m"], c["initial_velocity_m_per_s"], _num(c["peak_velocity_m_per_s"], 3), _num(c["t_peak"], 3),
                     _num(c["movement_time"], 3), _num(1e3 * c["final_error_m"], 2), c["success"]]
                    for c in report["phase"]["by_distance"] + report["phase"]["by_initial_velocity"]]),
            "", *_calibration_section(report["calibration"], settings), ""]


def _franka_section(section: dict, run_model: dict) -> list[str]:
    arm, summary, rows = section["model"], section["summary"], section["reaches"]
    build = (f"building the planner took {_num(section['planner_build_s'], 1)} s "
             + ("(its C functions were compiled on this run; later runs load them from the cache)"
                if section["compiled_on_this_run"] else "(compiled C functions loaded from the cache)"))
    warm = summary["warm_solve_time_median_s"]
    return [
        "## Franka Emika Panda (paper Section V-B; `franka_*.png`)", "",
        *([f"Arm model `{arm['name']}`: {_model_line(arm)}.", ""] if arm["name"] != run_model["name"] else []),
        f"Reaches from rest at the ready pose q = {[round(v, 4) for v in section['home_position_rad']]} rad (hand at "
        f"{[round(v, 3) for v in section['home_ee_m']]} m, base frame) to goals at the offsets below. The first goal is "
        "solved cold (multi-start), each later one warm-started from the plan before it. Speed: ||J(μ_q) μ_q̇||; "
        "MT: first time after the peak with speed below 5 % of the peak (docs/formulation.md §6). Limit usage: largest fraction of the limit over the mean "
        "path (1 = at the limit; joint positions measured from the middle of their range), with its joint; 'after MT': the "
        "fastest joint once the hand has stopped (motion in the arm's null space). "
        f"The paper reports 1.3 s per solve; {build}.", "",
        f"**{summary['successes']}/{summary['reaches']} solves succeeded, {summary['within_width']}/{summary['reaches']} "
        f"end within the goal width, {summary['within_limits']}/{summary['reaches']} keep every limit. Cold solve "
        f"{_num(summary['cold_solve_time_s'], 2)} s; warm solves median {_num(warm, 2)} s, max "
        f"{_num(summary['warm_solve_time_max_s'], 2)} s. Largest usage: position {_num(summary['position_usage_max'], 2)}, "
        f"velocity {_num(summary['velocity_usage_max'], 2)}, torque {_num(summary['torque_usage_max'], 2)}; joint velocity "
        f"after the hand has stopped {_num(summary['velocity_usage_after_mt_max'], 2)}.**", "",
        _table(["goal offset", "D (m)", "w (m)", "status", "start", "solve time (s)", "iterations", "final error (mm)",
                "within w", "t_peak (s)", "MT (s)", "t_peak/MT", "peak speed (m/s)", "final speed (m/s)",
                "position usage (joint)", "velocity usage (joint)", "torque usage (joint)", "velocity usage after MT",
                "within limits"],
               [[r["goal_label"], _num(r["distance_m"], 3), r["width_m"], r["status"], "warm" if r["warm_started"] else "cold",
                 _num(r["solve_time_s"], 2), r["iterations"], _num(1e3 * r["final_error_m"], 1), r["within_width"],
                 _num(r["t_peak"], 3), _num(r["movement_time"], 3), _num(r["asymmetry"], 2), _num(r["peak_speed"], 3),
                 _num(r["final_speed"], 3),
                 *(f"{_num(r[f'{kind}_usage_max'], 2)} ({r[f'{kind}_usage_joint']})" for kind in LIMIT_KINDS),
                 _num(r["velocity_usage_after_mt"], 2), r["within_limits"]] for r in rows]),
        "", "Per-reach rows: `franka_reaches.csv`; every plan step by step: `franka_plans/goal_<k>.csv`.", "",
    ]


def _calibration_section(calibration: dict, settings: dict) -> list[str]:
    rows = calibration["configurations"]
    both = calibration["both"]
    verdict = (f"Configurations with both Fitts' law and an early peak: {', '.join(both)}." if both else
               f"Configurations with both Fitts' law and an early peak: none of the {len(rows)} on this grid.")
    return [
        "## Calibration study (`calibration.png`)", "",
        f"Grid D ∈ {list(settings['distances'])} m × w ∈ {list(settings['widths'])} m. Fitts' law: every reach finished, "
        f"best R² ≥ {FITTS_R2_MIN}, both trends in every pair, every MT in the human range. Early peak: t_peak/MT < "
        f"{EARLY_PEAK_MAX} in every condition. The last column fits t_peak/MT against the effective ID "
        "log2(2D/√W) (√W = w for W = w²I, √w for W = wI) and says where the line crosses 0.5. Closed loop: mean "
        f"executed velocity over {settings['calibration_trials']} trials per condition, replanning every step from the noisy state (window H, 2H steps).", "",
        verdict, "",
        f"Reference: under W = wI a scale-invariant model's MT depends on D/√w rather than D/w; an MT exactly linear in "
        f"log2(2D/√w) would reach only R² = {_num(calibration['cov_reading_fitts_r2_if_log_linear'], 3)} (Fitts form) / "
        f"{_num(calibration['cov_reading_shannon_r2_if_log_linear'], 3)} (Shannon form) on this grid.", "",
        _table(["configuration", "mode", "t_peak/MT min / median / max", "early (share)", "MT range (s)", "R² Fitts",
                "R² Shannon", "slope (s/bit)", "width trend", "distance trend", "converged", "Fitts' law", "early peak",
                "t_peak/MT = 0.5 at effective ID (bits)"],
               [[r["configuration"], r["mode"],
                 f"{_num(r['asymmetry_min'], 2)} / {_num(r['asymmetry_median'], 2)} / {_num(r['asymmetry_max'], 2)}",
                 _num(r["early_fraction"], 2), f"{_num(r['mt_min_s'], 3)}–{_num(r['mt_max_s'], 3)}", _num(r["fitts_r2"], 3),
                 _num(r["shannon_r2"], 3), _num(r["fitts_slope_s_per_bit"], 4), _num(r["width_trend"], 2),
                 _num(r["distance_trend"], 2), r["all_solves_converged"], "yes" if r["fitts_law"] else "no",
                 "yes" if r["early_peak"] else "no", _num(r["effective_id_at_half_bits"], 2)] for r in rows]),
    ]


def human_targets_markdown(section: dict) -> list[str]:
    """Lines of the report section."""
    models = section["models"]
    samples = models[0]["conditions"][0]["samples"]
    lines = ["## Human-likeness targets (`human_targets.png`)", "",
             f"Open-loop plans from rest, measured on the plan's mean; {section['definition']}. MT: first time after the "
             "peak with speed below 5 % of the peak (docs/formulation.md §6; minimum jerk then has t_peak/MT = "
             f"{minimum_jerk_asymmetry():.3f}). The hand is scored at the first step at or after MT: hit rate in closed "
             f"form (Gaussian with the plan's predicted mean and covariance, integrated over the ball) and over {samples} "
             "open-loop Monte Carlo executions of the planned torques under the model's noise. 'Onset': speed 50 ms "
             "after the start over the peak speed (the column 'min-jerk' gives a minimum-jerk reach with the same MT, "
             "for reference). The endpoint-SD target uses the closed-form SD along and across the reach.", "",
             verdict_table(section), ""]
    for model in models:
        lines += [f"### {model['model']}: per condition", "", _condition_table(model["conditions"]), ""]
    return lines


def verdict_table(section: dict) -> str:
    """The targets as rows, each model's measured value (range over conditions) and pass/fail as columns."""
    models = section["models"]
    header = ["target", "threshold"]
    for model in models:
        header += [f"{model['model']}: measured", f"{model['model']}: verdict"]
    rows = []
    for k, first in enumerate(models[0]["verdicts"]):
        row = [first["target"] + (f" ({first['unit']})" if first["unit"] else ""), first["threshold"]]
        for model in models:
            verdict = model["verdicts"][k]
            row += [_range(verdict["low"], verdict["high"]), _pass(verdict)]
        rows.append(row)
    totals = ["**targets passed**", ""]
    for model in models:
        totals += ["", f"**{model['passed']} / {model['targets']}**"]
    return _table(header, rows + [totals])


def _condition_table(conditions: list[dict]) -> str:
    header = ["D (m)", "w (m)", "ID (bits)", "MT (s)", "t_peak/MT", "peak speed / (D/MT)", "onset", "onset min-jerk",
              "peaks", "reversal", "end speed", "hit rate closed form", "hit rate Monte Carlo", "SD along / across (mm)",
              "SD along / across closed form (mm)", "converged"]
    rows = [[c["distance"], c["width"], _num(c["index_of_difficulty"], 2), _num(c["movement_time"], 3),
             _num(c["asymmetry"], 3), _num(c["peak_speed_ratio"], 2), _num(c["onset"], 3), _num(c["onset_minimum_jerk"], 3),
             c["peaks"], _num(c["reversal"], 3), _significant(c["end_speed"]), _num(c["hit_rate_closed_form"], 3),
             _num(c["hit_rate_monte_carlo"], 3), f"{_num(1e3 * c['sd_along'], 1)} / {_num(1e3 * c['sd_across'], 1)}",
             f"{_num(1e3 * c['sd_along_predicted'], 1)} / {_num(1e3 * c['sd_across_predicted'], 1)}", c["success"]]
            for c in conditions]
    return _table(header, rows)


def _range(low, high) -> str:
    """'low … high' with three significant digits; one number when both read the same."""
    low, high = _significant(low), _significant(high)
    return low if low == high else f"{low} … {high}"


def _pass(verdict: dict) -> str:
    if verdict["passed"]:
        return "pass"
    failing = verdict["failing"]
    return f"**fail** ({len(failing)}/{verdict['checked']})" if failing else "**fail**"


def _significant(value) -> str:
    """Three significant digits; '–' for a missing (None) or non-finite value."""
    return f"{value:.3g}" if value is not None and math.isfinite(value) else "–"


def _table(header: list[str], rows: list[list]) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(v) for v in row) + " |" for row in rows]
    return "\n".join(out)


def _num(value, digits: int) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "–"
    return f"{value:.{digits}f}"
