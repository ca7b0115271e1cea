"""What the paper's Section IV-D analyses claim and what the run's model gives, side by side: the headline of
``comanip validate`` and the first table of its ``report.md``. Each row is one claim of the paper, where the
paper shows it, and the model's measured counterpart, in words and numbers (no verdict: the numbers are for
the reader to compare)."""

from __future__ import annotations


def paper_comparison(report: dict) -> list[dict]:
    """Rows {claim, paper, model} from a validation report (:func:`comanip.validation.run.run_validation`); none
    for a report without the point-mass analyses (an arm preset's)."""
    if "fitts_grid" not in report:
        return []
    grid, dispersion = report["fitts_grid"], report["dispersion"]["widths"]
    fits = grid["fits"]
    asymmetry = [c["asymmetry"] for c in grid["conditions"]]
    times = [c["movement_time"] for c in grid["conditions"]]
    low, high = grid["human_mt_range_s"]
    spread = " → ".join(f"{1e3 * d['across_std']:.1f}" for d in dispersion)
    widths = " → ".join(f"{1e3 * d['width']:g}" for d in dispersion)
    return [
        {"claim": "movement time is linear in the index of difficulty (Fitts' law)", "paper": "Fig. 3, bottom",
         "model": f"R² {fits['fitts']['r2']:.3f} (Fitts form), {fits['shannon']['r2']:.3f} (Shannon form), "
                  f"slope {fits['fitts']['b']:.3f} s/bit"},
        {"claim": "wider goals are reached no slower, farther goals slower", "paper": "Fig. 3, bottom",
         "model": f"{100 * grid['width_trend']:.0f} % and {100 * grid['distance_trend']:.0f} % of neighbouring pairs"},
        {"claim": "movement times of human reaches", "paper": "Fig. 3, bottom",
         "model": f"{min(times):.2f}–{max(times):.2f} s (human range {low}–{high} s)"},
        {"claim": "bell-shaped speed profiles", "paper": "Fig. 3, top",
         "model": f"peak at {min(asymmetry):.2f}–{max(asymmetry):.2f} of the movement time (minimum jerk: "
                  f"{grid['minimum_jerk_asymmetry']:.3f})"},
        {"claim": "the endpoint spread grows with the goal width", "paper": "Fig. 4",
         "model": f"across the reach {spread} mm for w = {widths} mm"},
    ]


def comparison_lines(report: dict) -> list[str]:
    """The comparison as terminal lines: 'paper (where): claim — model: ...'."""
    return [f"paper ({row['paper']}): {row['claim']} — model: {row['model']}" for row in paper_comparison(report)]
