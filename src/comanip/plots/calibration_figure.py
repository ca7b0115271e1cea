"""The calibration study at a glance: per configuration, the range of t_peak/MT and the Fitts fit."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.analysis.calibration import EARLY_PEAK_MAX, FITTS_R2_MIN
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_asymmetry
from comanip.plots.figure_file import save_figure


def plot_calibration(rows: list[dict], path: str | Path, title: str = "") -> Path:
    """Save a PNG from calibration summary rows (:meth:`CalibrationResult.summary`): left, t_peak/MT over the
    grid (bar from min to max, dot at the median) with the 0.5 claim and the minimum-jerk value; right, the
    better of the Fitts and Shannon R². Green rows get Fitts' law (every criterion), grey rows do not."""
    fig, (ax_ratio, ax_r2) = plt.subplots(1, 2, figsize=(12, 0.32 * len(rows) + 2.4), sharey=True,
                                          gridspec_kw={"width_ratios": [3, 2]})
    y = np.arange(len(rows))[::-1]
    for yi, row in zip(y, rows):
        color = "C2" if row["fitts_law"] else "0.5"
        marker = "s" if row["mode"] == "closed loop" else "o"
        ax_ratio.plot([row["asymmetry_min"], row["asymmetry_max"]], [yi, yi], color=color, lw=4, alpha=0.6)
        ax_ratio.plot(row["asymmetry_median"], yi, marker, color="k", ms=4)
        best = np.nanmax([row["fitts_r2"], row["shannon_r2"], 0.0])
        ax_r2.barh(yi, best, color=color, alpha=0.7)
    ax_ratio.axvline(EARLY_PEAK_MAX, color="C3", ls="--", lw=1, label=f"claim: t_peak/MT < {EARLY_PEAK_MAX}")
    ax_ratio.axvline(minimum_jerk_asymmetry(), color="C0", ls=":", lw=1, label=f"minimum jerk ({minimum_jerk_asymmetry():.3f})")
    ax_ratio.plot([], [], "ok", ms=4, label="median (open loop)")
    ax_ratio.plot([], [], "sk", ms=4, label="median (closed loop)")
    ax_ratio.set(yticks=y, yticklabels=[f"{r['configuration']}" for r in rows], xlabel="t_peak / MT over the grid (min–max)")
    # below the axes, where it cannot cover a bar
    ax_ratio.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=4, frameon=False)
    ax_ratio.grid(alpha=0.3, axis="x")
    ax_r2.axvline(FITTS_R2_MIN, color="C3", ls="--", lw=1)
    ax_r2.set(xlabel="best R² (Fitts or Shannon); green: Fitts' law holds", xlim=(0, 1))
    ax_r2.grid(alpha=0.3, axis="x")
    return save_figure(fig, path, title or "calibration study")
