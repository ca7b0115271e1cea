"""Figure of a hand streamed through the online estimator: its path with the goal estimated at each sample, and the
goal and the hand over time."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.plots.figure_file import save_figure


def plot_streamed_estimates(t: np.ndarray, hand: np.ndarray, goals: np.ndarray, path: str | Path, title: str = "") -> Path:
    """Two panels: the hand's path (first two axes) with each sample's estimated goal coloured by time; the goal's
    and the hand's coordinates over time. t (K,) s, hand (K, d) m, goals (K, d) m (NaN rows before a reach)."""
    fig, (ax_path, ax_time) = plt.subplots(1, 2, figsize=(11, 4.2))
    y = hand[:, 1] if hand.shape[1] > 1 else np.zeros(len(hand))
    ax_path.plot(hand[:, 0], y, "k-", lw=1.5, label="hand")
    known = np.all(np.isfinite(goals), axis=1)
    dots = ax_path.scatter(goals[known, 0], goals[known, 1] if goals.shape[1] > 1 else np.zeros(known.sum()),
                           c=t[known], cmap="viridis", s=12, label="estimated goal")
    fig.colorbar(dots, ax=ax_path, label="t (s)")
    ax_path.set(xlabel="x (m)", ylabel="y (m)", title="the hand and the goal estimated as it moves")
    ax_path.axis("equal")
    ax_path.legend(fontsize=8)
    for k, axis in enumerate("xyz"[: hand.shape[1]]):
        ax_time.plot(t, hand[:, k], "--", color=f"C{k}", lw=1, label=f"hand {axis}")
        ax_time.plot(t, goals[:, k], "-", color=f"C{k}", label=f"goal {axis}")
    ax_time.set(xlabel="t (s)", ylabel="m", title="goal and hand over time")
    ax_time.legend(fontsize=8, ncol=2)
    return save_figure(fig, path, title)
