"""Figure of the simulated synchronisation scenario (paper Fig. 7): velocity profiles, and the error between
the robot's estimated trajectory and the handle over normalised time, mean ± std over trials per goal."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.plots.figure_file import save_figure
from comanip.simulation.sync_scenario import SyncTrial


def _band(ax, x, values, color, label, ls="-"):
    """Mean line and ±1 std band of values (N, K) over x (K,)."""
    mean, std = values.mean(axis=0), values.std(axis=0)
    ax.plot(x, mean, color=color, ls=ls, lw=1.8, label=label)
    ax.fill_between(x, mean - std, mean + std, color=color, alpha=0.18, lw=0)


def plot_sync(runs: dict[str, list[SyncTrial]], observation_time: float, path: str | Path, title: str = "") -> Path:
    """Save the figure for runs {goal label: trials}: top, speeds over time of the handle (the robot's end
    effector, solid), the person's intended hand (dashed) and the robot's estimated trajectory (dotted);
    bottom, the robot's last prediction of the path (the one it ended with) minus the handle per axis over t / MT
    (from t_o on): not the goal estimate's error, which the summary reports."""
    fig = plt.figure(figsize=(12, 7.5))
    grid = fig.add_gridspec(2, 3, height_ratios=[1.1, 1.0])
    ax_speed = fig.add_subplot(grid[0, :])
    ax_error = [fig.add_subplot(grid[1, a]) for a in range(3)]
    colors = plt.cm.tab10(np.arange(len(runs)))
    for color, (label, trials) in zip(colors, runs.items()):
        t = trials[0].record.t
        handle = np.stack([np.linalg.norm(tr.record.velocity, axis=1) for tr in trials])
        person = np.stack([np.linalg.norm(tr.record.intended_velocity, axis=1) for tr in trials])
        estimated = np.stack([np.linalg.norm(np.gradient(tr.estimated_position, t, axis=0), axis=1) for tr in trials])
        _band(ax_speed, t, handle, color, f"{label}: robot end effector")
        _band(ax_speed, t, person, color, f"{label}: person's intention", ls="--")
        ax_speed.plot(t, estimated.mean(axis=0), color=color, ls=":", lw=1.5, label=f"{label}: robot's estimate")
        for a, ax in enumerate(ax_error):
            grid_t = trials[0].normalised_time
            errors = 1e3 * np.stack([tr.normalised_error[:, a] for tr in trials])
            after = grid_t * np.mean([tr.metrics["movement_time_s"] for tr in trials]) >= observation_time
            _band(ax, grid_t[after], errors[:, after], color, label)
    ax_speed.axvline(observation_time, color="gray", ls="-.", lw=1)
    ax_speed.text(observation_time, ax_speed.get_ylim()[1] * 0.95, " t_o: estimate", color="gray", fontsize=8, va="top")
    ax_speed.set(xlabel="t (s)", ylabel="speed (m/s)", title="velocity profiles (mean ± std over trials)")
    ax_speed.legend(fontsize=8, ncol=2)
    ax_speed.grid(alpha=0.3)
    for axis, ax in zip("xyz", ax_error):
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set(xlabel="t / MT", ylabel=f"{axis} error (mm)", title=f"the last prediction's path − the handle, {axis}")
        ax.grid(alpha=0.3)
    ax_error[0].legend(fontsize=8)
    return save_figure(fig, path, title or "co-manipulation synchronisation (simulated)")
