"""Position–velocity phase plots along the reach direction over goal distances and initial velocities (paper Fig. 5)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.analysis.phase import PhaseCurve
from comanip.plots.figure_file import save_figure


def plot_phase(by_distance: list[PhaseCurve], by_velocity: list[PhaseCurve], path: str | Path, title: str = "") -> Path:
    """Save a two-panel PNG: phase curves for several goal distances (left) and initial velocities (right)."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True)
    for ax, curves, label in ((axes[0], by_distance, lambda c: f"D = {c.distance:g} m"),
                              (axes[1], by_velocity, lambda c: f"v0 = {c.initial_velocity:+g} m/s")):
        colors = plt.cm.viridis(np.linspace(0.0, 0.85, max(len(curves), 1)))
        for color, curve in zip(colors, curves):
            ax.plot(curve.position, curve.velocity, ".-", color=color, ms=3,
                    label=label(curve) + ("" if curve.success else " (not converged)"))
            ax.axvline(curve.distance, color=color, ls=":", lw=1)
        ax.set(xlabel="position along the reach (m)", title="goal distances" if ax is axes[0] else
               f"initial velocities (D = {curves[0].distance:g} m)" if curves else "initial velocities")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("velocity along the reach (m/s)")
    return save_figure(fig, path, title or "phase plots")
