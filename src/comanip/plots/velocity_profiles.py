"""Velocity profiles across goal widths and distances, with the minimum-jerk baseline and Fitts-predicted
finish times (paper Fig. 3, top)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.analysis.fitts import FittsFit
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_velocity
from comanip.analysis.reach_grid import ReachOutcome
from comanip.plots.figure_file import save_figure


def plot_velocity_profiles(outcomes: list[ReachOutcome], fit: FittsFit, fixed_distance: float, fixed_width: float,
                           path: str | Path, title: str = "") -> Path:
    """Save a two-panel PNG: speed over time for every width at fixed_distance (m), and for every distance at
    fixed_width (m). Solid: the model; dashed: minimum jerk with the same movement time; dotted vertical
    lines: the movement time the Fitts fit predicts for that condition."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), sharey=True)
    panels = [(axes[0], [o for o in outcomes if np.isclose(o.distance, fixed_distance)], "width", f"D = {fixed_distance:g} m"),
              (axes[1], [o for o in outcomes if np.isclose(o.width, fixed_width)], "distance", f"w = {fixed_width:g} m")]
    for ax, chosen, varied, fixed_label in panels:
        colors = plt.cm.viridis(np.linspace(0.0, 0.85, max(len(chosen), 1)))
        for color, outcome in zip(colors, chosen):
            value = getattr(outcome, varied)
            label = f"{varied[0] if varied == 'width' else 'D'} = {value:g} m"
            ax.plot(outcome.t, outcome.speed, color=color, lw=2, label=label)
            if outcome.metrics.settled:
                t_fine = np.linspace(outcome.t[0], outcome.t[-1], 400)
                # speed is a norm, so a one-dimensional reach of the same distance gives the baseline's speed
                baseline = minimum_jerk_velocity([0.0], [outcome.distance], outcome.metrics.movement_time, t_fine)
                ax.plot(t_fine, np.abs(baseline[:, 0]), color=color, lw=1, ls="--")
            ax.axvline(float(fit.predict(outcome.distance, outcome.width)), color=color, ls=":", lw=1.2)
        ax.plot([], [], color="gray", ls="--", lw=1, label="minimum jerk, same MT")
        ax.plot([], [], color="gray", ls=":", lw=1.2, label=f"{fit.form.capitalize()} fit: predicted MT")
        ax.set(xlabel="t (s)", title=f"speed at {fixed_label}")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("hand speed (m/s)")
    return save_figure(fig, path, title or "velocity profiles")
