"""t_peak/MT against the effective index of difficulty, every condition of every calibration configuration.

The effective ID uses the goal's standard deviation sqrt(W) in place of w: log2(2D / sqrt(W)), with
sqrt(W) = w under the 'std' reading and sqrt(w) under 'cov'. Plotted this way the two readings fall on
one curve per execution mode, which shows why the early peak and Fitts' law part ways
(docs/results/calibration.md)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.analysis.calibration import EARLY_PEAK_MAX
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_asymmetry
from comanip.plots.figure_file import save_figure


def plot_asymmetry_against_difficulty(rows: list[dict], nominal_id_range: tuple[float, float], path: str | Path,
                                      title: str = "") -> Path:
    """Save a PNG from calibration summary rows: one marker per condition at (effective ID, t_peak/MT),
    colour by W reading and execution mode; the grid's nominal Fitts ID range (bits) shaded."""
    fig, ax = plt.subplots(figsize=(8, 5))
    styles = {("std", "open loop"): ("o", "C0"), ("cov", "open loop"): ("o", "C1"),
              ("std", "closed loop"): ("s", "C2"), ("cov", "closed loop"): ("s", "C3")}
    readings = {"std": "W = w²I", "cov": "W = wI"}
    labelled = set()
    for row in rows:
        form = row["goal_covariance"]
        x, y = np.array([(c["effective_id_bits"], c["asymmetry"]) for c in row["conditions"]], dtype=float).T
        marker, color = styles[form, row["mode"]]
        label = None if (form, row["mode"]) in labelled else f"{readings[form]}, {row['mode']}"
        labelled.add((form, row["mode"]))
        ax.plot(x, y, marker, color=color, ms=5, alpha=0.6, label=label)
    ax.axhline(EARLY_PEAK_MAX, color="C3", ls="--", lw=1, label=f"claim: t_peak/MT < {EARLY_PEAK_MAX}")
    ax.axhline(minimum_jerk_asymmetry(), color="C0", ls=":", lw=1, label="minimum jerk")
    ax.axvspan(*nominal_id_range, color="0.85", alpha=0.5, zorder=0, label="grid's Fitts ID range (std reading)")
    ax.set(xlabel="effective ID = log2(2D / sqrt(W)) (bits)", ylabel="t_peak / MT")
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    ax.set_title(title or "velocity-peak timing against the difficulty the model sees", fontsize=10)
    return save_figure(fig, path)
