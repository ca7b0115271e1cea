"""Movement time against the index of difficulty with the linear fits, Fitts and Shannon forms (paper Fig. 3, bottom)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.analysis.fitts import FittsFit, index_of_difficulty
from comanip.analysis.reach_grid import ReachOutcome
from comanip.plots.figure_file import save_figure


def plot_fitts(outcomes: list[ReachOutcome], fits: list[FittsFit], path: str | Path, title: str = "") -> Path:
    """Save a PNG with one panel per fit: MT (s) of each outcome against its ID (bits), coloured by distance,
    marked by width, with the fitted line and its R²."""
    fig, axes = plt.subplots(1, len(fits), figsize=(5.5 * len(fits), 4.2), squeeze=False)
    distances = sorted({o.distance for o in outcomes})
    widths = sorted({o.width for o in outcomes})
    colors = dict(zip(distances, plt.cm.viridis(np.linspace(0.0, 0.85, len(distances)))))
    markers = dict(zip(widths, "o^sDvP*X"))
    for ax, fit in zip(axes[0], fits):
        ids = np.array([float(index_of_difficulty(o.distance, o.width, fit.form)) for o in outcomes])
        for o, x in zip(outcomes, ids):
            ax.plot(x, o.metrics.movement_time, ls="", marker=markers[o.width], color=colors[o.distance], ms=7)
        line = np.linspace(ids.min() - 0.2, ids.max() + 0.2, 2)
        ax.plot(line, fit.a + fit.b * line, "k-", lw=1,
                label=f"MT = {fit.a:.3f} + {fit.b:.3f}·ID  (R² = {fit.r2:.3f})")
        for D in distances:
            ax.plot([], [], ls="", marker="o", color=colors[D], label=f"D = {D:g} m")
        for w in widths:
            ax.plot([], [], ls="", marker=markers[w], color="gray", label=f"w = {w:g} m")
        formula = "log2(2D/w)" if fit.form == "fitts" else "log2(D/w + 1)"
        ax.set(xlabel=f"ID = {formula} (bits)", ylabel="movement time (s)", title=f"{fit.form.capitalize()} form")
        ax.legend(fontsize=7, ncol=2)
        ax.grid(alpha=0.3)
    return save_figure(fig, path, title or "Fitts' law")
