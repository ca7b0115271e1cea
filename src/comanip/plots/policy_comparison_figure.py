"""Figure comparing robot policies on the synchronisation scenario: the goal-estimate error over time
(median and interquartile band over trials, one panel per goal) and, per measure, each policy's trials as
box plots (whiskers: 1.5 IQR) per goal."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.patches import Patch
import numpy as np

from comanip.plots.figure_file import save_figure
from comanip.simulation.sync_scenario import SyncTrial

BOXED = {"goal_error_mean_m": ("goal error, mean t_o–MT (mm)", 1e3),
         "rms_force_change_N": ("RMS force change (N)", 1.0),
         "work_against_robot_J": ("work against robot (J)", 1.0),
         "sync_error_rms": ("sync error x–y vs z (% of reach)", 100.0)}
"""Measures drawn as box plots: key in the trial metrics -> (axis label, scale)."""


def plot_policy_comparison(results: dict[str, dict[str, list[SyncTrial]]], path: str | Path, title: str = "") -> Path:
    """Save the figure for results {goal label: {policy: trials}}."""
    goals = list(results)
    policies = list(next(iter(results.values())))
    colors = dict(zip(policies, plt.cm.tab10(np.arange(len(policies)))))
    fig, axes = plt.subplots(2, max(len(goals), len(BOXED)), figsize=(4.2 * max(len(goals), len(BOXED)), 8.0), squeeze=False)
    for ax, goal in zip(axes[0], goals):
        for name, trials in results[goal].items():
            estimates = np.stack([trial.record.goal_estimate for trial in trials])        # (N, K, 3)
            if not np.any(np.isfinite(estimates)):
                continue
            t = trials[0].record.t
            error = 1e3 * np.linalg.norm(estimates - np.stack([trial.record.goal for trial in trials])[:, None], axis=2)
            q25, median, q75 = np.full((3, t.size), np.nan)
            seen = np.any(np.isfinite(error), axis=0)  # before the first estimate no trial has one
            q25[seen], median[seen], q75[seen] = np.nanpercentile(error[:, seen], [25, 50, 75], axis=0)
            ax.plot(t, median, color=colors[name], lw=1.6, label=name)
            ax.fill_between(t, q25, q75, color=colors[name], alpha=0.2, lw=0)
        estimated = bool(ax.lines)  # False when every policy estimates nothing (passive)
        if not estimated:
            ax.text(0.5, 0.5, "no goal estimates", transform=ax.transAxes, ha="center", va="center", color="gray")
        mt = np.median([trial.metrics["movement_time_s"] for trials in results[goal].values() for trial in trials])
        ax.axvline(mt, color="gray", ls=":", lw=1)
        ax.set(xlabel="t (s)", ylabel="goal-estimate error (mm)", title=f"{goal}: goal error (median, IQR)",
               yscale="log" if estimated else "linear")
        ax.grid(alpha=0.3, which="both")
    if axes[0, 0].get_legend_handles_labels()[0]:
        axes[0, 0].legend(fontsize=8)
    for ax in axes[0, len(goals):]:
        ax.set_visible(False)
    for ax, (key, (label, scale)) in zip(axes[1], BOXED.items()):
        width = 0.8 / len(policies)
        for i, name in enumerate(policies):
            data = [[scale * v for v in (trial.metrics[key] for trial in results[goal][name]) if np.isfinite(v)] for goal in goals]
            positions = np.arange(len(goals)) + (i - (len(policies) - 1) / 2) * width
            kept = [(p, d) for p, d in zip(positions, data) if d]
            if not kept:
                continue
            box = ax.boxplot([d for _, d in kept], positions=[p for p, _ in kept], widths=0.9 * width, patch_artist=True,
                             showfliers=False, medianprops={"color": "k"})
            for patch in box["boxes"]:
                patch.set_facecolor(colors[name])
                patch.set_alpha(0.7)
        ax.set_xticks(np.arange(len(goals)), goals)
        ax.set(ylabel=label)
        ax.grid(alpha=0.3, axis="y")
    axes[1, 0].legend(handles=[Patch(facecolor=colors[name], alpha=0.7, label=name) for name in policies], fontsize=8)
    for ax in axes[1, len(BOXED):]:
        ax.set_visible(False)
    return save_figure(fig, path, title or "robot policies on the synchronisation scenario (simulated person, same seeds)")
