"""Paper Fig. 2: the transition model's predicted distance from the goal over (D/L, w), with its data."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

from comanip.multicomponent.transition_model import TransitionModel


def plot_transition_model(model: TransitionModel, path: str | Path, margin: float = 0.15, resolution: int = 60) -> Path:
    """Save a three-panel PNG: mean transition distance over (D/L, w) with the data points; slices over D/L per
    data width with ±2σ bands; the model's std. The grid reaches ``margin`` of each range beyond the data
    (dashed box) so the growth of the std away from the data shows."""
    data = model.training_data
    (r_lo, r_hi), (w_lo, w_hi) = model.data_range.values()
    r_pad, w_pad = margin * (r_hi - r_lo), margin * (w_hi - w_lo)
    ratios = np.linspace(max(r_lo - r_pad, 1e-3), r_hi + r_pad, resolution)
    widths = np.linspace(max(w_lo - w_pad, 1e-4), w_hi + w_pad, resolution)
    R, W = np.meshgrid(ratios, widths)
    mean, variance = model.posterior(R.ravel(), W.ravel(), full_covariance=False)
    mean, std = mean.reshape(R.shape), np.sqrt(variance).reshape(R.shape)
    T = data["transition_distance_m"]

    fig, (ax_map, ax_slices, ax_std) = plt.subplots(1, 3, figsize=(15, 4.4))
    levels = np.linspace(min(mean.min(), T.min()), max(mean.max(), T.max()), 15)
    filled = ax_map.contourf(R, 1e3 * W, mean, levels=levels, cmap="viridis")
    ax_map.scatter(data["distance_over_arm_length"], 1e3 * data["width_m"], c=T, cmap="viridis", norm=filled.norm,
                   edgecolors="k", s=30, label="data")
    fig.colorbar(filled, ax=ax_map, label="transition distance from goal (m)", format="%.2f")
    ax_map.set(xlabel="goal distance D/L", ylabel="goal width w (mm)", title="predicted transition distance")
    ax_map.legend(loc="upper left", fontsize=8)

    unique = np.unique(data["width_m"])
    slice_widths = unique if len(unique) <= 8 else np.linspace(w_lo, w_hi, 5)
    width_norm = plt.Normalize(1e3 * w_lo, 1e3 * w_hi)
    for w in slice_widths:
        colour = plt.cm.plasma(width_norm(1e3 * w))
        m, v = model.posterior(ratios, np.full_like(ratios, w), full_covariance=False)
        band = 2 * np.sqrt(v)
        ax_slices.plot(ratios, m, color=colour)
        ax_slices.fill_between(ratios, m - band, m + band, color=colour, alpha=0.15)
    points = ax_slices.scatter(data["distance_over_arm_length"], T, c=1e3 * data["width_m"], cmap="plasma",
                               norm=width_norm, s=14, edgecolors="k", linewidths=0.3, zorder=3)
    fig.colorbar(points, ax=ax_slices, label="goal width w (mm)")
    ax_slices.axvspan(r_lo, r_hi, color="0.92", zorder=0)
    ax_slices.set(xlabel="goal distance D/L", ylabel="transition distance from goal (m)",
                  title=f"slices at {len(slice_widths)} widths, ±2σ (grey: data range)")

    shaded = ax_std.contourf(R, 1e3 * W, 1e3 * std, levels=15, cmap="magma")
    ax_std.plot(data["distance_over_arm_length"], 1e3 * data["width_m"], "w.", ms=4)
    fig.colorbar(shaded, ax=ax_std, label="model std (mm)")
    ax_std.set(xlabel="goal distance D/L", ylabel="goal width w (mm)", title="model uncertainty")
    for ax in (ax_map, ax_std):
        ax.add_patch(Rectangle((r_lo, 1e3 * w_lo), r_hi - r_lo, 1e3 * (w_hi - w_lo), fill=False, ls="--", color="w"))
    fig.suptitle(f"Transition model (GP, {len(T)} conditions): {model.kernel_description}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
