"""Dispersion of open-loop executions: sampled hand paths, and histograms of the hand's offset across the
movement at the movement time with fitted Gaussians (paper Fig. 4)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle
from scipy.stats import norm

from comanip.analysis.open_loop_dispersion import EndpointDispersion
from comanip.plots.figure_file import save_figure


def plot_dispersion(dispersions: list[EndpointDispersion], goal, path: str | Path, max_paths: int = 60,
                    title: str = "") -> Path:
    """Save a PNG: top row, up to max_paths sampled paths per width (first two task axes) with the goal
    (circle of radius w); bottom row, histogram of across offsets (mm) with the fitted Gaussian."""
    goal = np.asarray(goal, dtype=float)
    fig, axes = plt.subplots(2, len(dispersions), figsize=(5.5 * len(dispersions), 7), squeeze=False)
    for k, dispersion in enumerate(dispersions):
        ax_path, ax_hist = axes[0, k], axes[1, k]
        for sample in dispersion.paths[:max_paths]:
            ax_path.plot(sample[: dispersion.step + 1, 0], sample[: dispersion.step + 1, 1], color="C0", lw=0.6, alpha=0.4)
        ends = dispersion.paths[:, dispersion.step]
        ax_path.plot(ends[:, 0], ends[:, 1], ".", color="C3", ms=2, label=f"hand at MT ({dispersion.time:.2f} s)")
        ax_path.add_patch(Circle(goal[:2], dispersion.width, color="g", alpha=0.25, label=f"goal, w = {dispersion.width:g} m"))
        ax_path.set(xlabel="x (m)", ylabel="y (m), stretched", title=f"{len(dispersion.paths)} open-loop executions (showing {min(max_paths, len(dispersion.paths))})")
        ax_path.legend(fontsize=7, loc="upper left")
        ax_path.grid(alpha=0.3)

        offsets_mm = 1e3 * dispersion.across_offsets
        ax_hist.hist(offsets_mm, bins=30, color="C0", alpha=0.7, density=True, label="hits (density)")
        grid = np.linspace(offsets_mm.min(), offsets_mm.max(), 200)
        ax_hist.plot(grid, norm.pdf(grid, 1e3 * dispersion.across_fit_mean, 1e3 * dispersion.across_fit_std), color="C1",
                     lw=2, label=f"fitted Gaussian, std {1e3 * dispersion.across_fit_std:.2f} mm")
        for edge in (-1e3 * dispersion.width, 1e3 * dispersion.width):
            ax_hist.axvline(edge, color="g", ls="--", lw=1)
        ax_hist.set(xlabel="offset across the movement at MT (mm)", ylabel="density",
                    title=f"w = {dispersion.width:g} m: hit rate {100 * dispersion.hit_rate:.0f} %")
        ax_hist.legend(fontsize=7)
    return save_figure(fig, path, title or "endpoint dispersion")
