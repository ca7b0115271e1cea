"""Figure of the synchronisation task as the paper shows it (Fig. 7, top): the person's horizontal speed and the
robot's height speed over normalised time t / MT, mean ± std over the trials, one panel per goal and robot."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.plots.figure_file import save_figure
from comanip.simulation.measures import speed_profiles

#: Normalised times t / MT on which the profiles are drawn.
GRID = np.linspace(0.0, 1.2, 121)


def plot_speed_profiles(results: dict, path: str | Path, policies=None, title: str = "") -> Path:
    """Save the figure for results {goal: {policy: trials}} (trials with a ``record``): rows the policies (all, or
    those named), columns the goals; in each panel the x–y speed (the person's axes) and the z speed (the robot's)."""
    goals = list(results)
    policies = list(policies or next(iter(results.values())))
    fig, axes = plt.subplots(len(policies), len(goals), figsize=(3.2 * len(goals), 2.2 * len(policies)), sharex=True,
                             squeeze=False)
    for column, goal in enumerate(goals):
        for row, name in enumerate(policies):
            ax = axes[row, column]
            profiles = np.stack([speed_profiles(trial.record, GRID) for trial in results[goal][name]])   # (N, P, 2)
            for k, (label, color) in enumerate([("x–y speed (the person's axes)", "tab:blue"), ("z speed (the robot's axis)", "tab:orange")]):
                mean, std = np.nanmean(profiles[:, :, k], axis=0), np.nanstd(profiles[:, :, k], axis=0)
                ax.plot(GRID, mean, color=color, lw=1.5, label=label)
                ax.fill_between(GRID, mean - std, mean + std, color=color, alpha=0.2, lw=0)
            ax.axvline(1.0, color="gray", lw=0.6, ls=":")
            ax.grid(alpha=0.3)
            if row == 0:
                ax.set_title(goal, fontsize=9)
            if column == 0:
                ax.set_ylabel(f"{name}\nspeed (m/s)", fontsize=8)
            if row == len(policies) - 1:
                ax.set_xlabel("t / MT")
    axes[0, 0].legend(fontsize=7)
    return save_figure(fig, path, title or "the person's horizontal and the robot's height speed (mean ± std over trials)")
