"""Figure of the demo's online prediction of a recorded person's goal (:mod:`comanip.demo`)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.plots.figure_file import save_figure


def plot_online_prediction(prediction, path: str | Path) -> Path:
    """Two panels: the recorded hand path from its start with each update's estimated goal (coloured by time)
    and the target; the estimate's distance from the target over the movement, with its 2σ (largest axis)."""
    fig, (ax_path, ax_error) = plt.subplots(1, 2, figsize=(11, 4.2))
    ax_path.plot(prediction.position[:, 0], prediction.position[:, 1], "k-", lw=1.5, label="recorded hand")
    dots = ax_path.scatter(prediction.goal[:, 0], prediction.goal[:, 1], c=prediction.t, cmap="viridis", s=14,
                           label="estimated goal")
    ax_path.plot(*prediction.target, "r*", ms=14, label="where the person aimed")
    ax_path.plot(0.0, 0.0, "ko", ms=5)
    fig.colorbar(dots, ax=ax_path, label="time since onset (s)")
    ax_path.set(xlabel="x (m)", ylabel="y (m)", title="the hand and the goal predicted as it moves")
    ax_path.axis("equal")
    ax_path.legend(fontsize=8, loc="best")
    fraction = prediction.t / prediction.recording.movement_time
    sigma = 2 * prediction.goal_std.max(axis=1)
    ax_error.plot(fraction, 100 * prediction.error, ".-", label="|estimated goal − target|")
    ax_error.fill_between(fraction, 0, 100 * sigma, color="C0", alpha=0.15, label="2σ of the estimate (largest axis)")
    ax_error.set(xlabel="fraction of the movement time", ylabel="cm", title="prediction error over the reach",
                 ylim=(0, max(5.0, float(np.nanpercentile(100 * prediction.error, 95)) * 1.2)))
    ax_error.legend(fontsize=8)
    return save_figure(fig, path, f"online goal prediction of a recorded reach ({prediction.recording.name}, "
                                  f"{100 * prediction.recording.distance:.0f} cm in {prediction.recording.movement_time:.2f} s)")
