"""Figure of the simulated handover scenario (paper Fig. 8): the handle's position spread and its velocity
(mean ± std over trials) against the distance to the goal, the predicted transition marked."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.plots.figure_file import save_figure
from comanip.simulation.handover_scenario import HandoverRun


def plot_handover(runs: dict[str, HandoverRun], path: str | Path, title: str = "") -> Path:
    """Save the figure for runs {goal label: run}: top, perpendicular position spread (mm) over the distance
    to the goal (m); bottom, speed mean ± std. Dashed verticals: predicted transition distances; dots: where
    each trial actually switched. The distance axis runs from the start (left) to the goal (right)."""
    fig, (ax_spread, ax_speed) = plt.subplots(2, 1, figsize=(9, 7.5), sharex=True)
    colors = plt.cm.tab10(np.arange(len(runs)))
    for color, (label, run) in zip(colors, runs.items()):
        distance = run.distance_to_goal
        transition = run.schedule.transition_distance
        ax_spread.plot(distance, 1e3 * run.dispersion.dispersion, color=color, lw=1.8, label=f"{label}: spread")
        ax_spread.plot(run.dispersion.transition_distance, 1e3 * run.dispersion.peak_dispersion, "v", color=color,
                       ms=8, label=f"{label}: peak spread")
        ax_speed.plot(distance, run.speed_mean, color=color, lw=1.8, label=f"{label}: speed")
        ax_speed.fill_between(distance, run.speed_mean - run.speed_std, run.speed_mean + run.speed_std,
                              color=color, alpha=0.2, lw=0)
        switched = [tr.metrics["switch_distance_m"] for tr in run.trials if tr.metrics["switched"]]
        ax_speed.plot(switched, np.interp(switched, distance[::-1], run.speed_mean[::-1]), "o", color=color, ms=4,
                      label=f"{label}: switches")
        for ax in (ax_spread, ax_speed):
            ax.axvline(transition, color=color, ls="--", lw=1.2)
        ax_spread.text(transition, 0.0, f" predicted\n transition\n {transition:.3f} m", color=color, fontsize=8, va="bottom")
    ax_spread.set(ylabel="position spread ⊥ path (mm)", title="position spread over distance to goal (std over trials)")
    ax_speed.set(xlabel="distance to goal along the start→goal line (m)", ylabel="speed (m/s)", title="velocity over distance to goal (mean ± std)")
    for ax in (ax_spread, ax_speed):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax_speed.invert_xaxis()
    return save_figure(fig, path, title or "authority handover (simulated)")
