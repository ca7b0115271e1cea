"""The human-likeness targets of one or more models (:mod:`comanip.analysis.human_targets`) in one figure:
normalised speed profiles, one panel per model, then hit rates against their band, t_peak/MT against ID and
MT against ID with the Fitts fit, every model in each of these three panels."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import Normalize
from matplotlib.transforms import ScaledTranslation

from comanip.analysis.human_targets import HumanTargetsResult
from comanip.analysis.minimum_jerk_baseline import minimum_jerk_speed_fraction
from comanip.analysis.target_verdicts import HumanTargets
from comanip.plots.figure_file import save_figure

_MARKERS = "osD^v"


def plot_human_targets(results: list[HumanTargetsResult], path: str | Path, targets: HumanTargets = HumanTargets(),
                       title: str = "") -> Path:
    """Save the PNG; results: one per model."""
    panels = len(results) + 3
    columns = 4 if panels == 4 else 3
    rows = -(-panels // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(5.2 * columns, 4.6 * rows), squeeze=False)
    axes = axes.ravel()
    ids = np.concatenate([[r.index_of_difficulty for r in result.rows] for result in results])
    shade = Normalize(ids.min(), ids.max())
    for ax, result in zip(axes, results):
        _speed_panel(ax, result, shade)
    k = len(results)
    _hit_panel(axes[k], results, targets)
    _asymmetry_panel(axes[k + 1], results, targets)
    _fitts_panel(axes[k + 2], results)
    for extra in axes[panels:]:
        extra.axis("off")
    return save_figure(fig, path, title or "human-likeness targets")


def _speed_panel(ax, result: HumanTargetsResult, shade: Normalize) -> None:
    """Speed / peak against t / MT for every condition, coloured by ID (colour bar in the empty upper right),
    with minimum jerk dashed."""
    for row, outcome in zip(result.rows, result.outcomes):
        if np.isfinite(row.movement_time):
            ax.plot(outcome.t / row.movement_time, outcome.speed / outcome.speed.max(),
                    color=plt.cm.viridis(shade(row.index_of_difficulty)), lw=1.3)
    s = np.linspace(0.0, 1.6, 300)
    ax.plot(s, minimum_jerk_speed_fraction(s, 1.0), "k--", lw=1.2, label="minimum jerk")
    ax.axvline(1.0, color="gray", ls=":", lw=1)
    ax.set(xlabel="t / MT", ylabel="speed / peak speed", xlim=(0, 1.6), ylim=(-0.02, 1.05),
           title=f"{result.model_name}: speed profiles")
    ax.legend(fontsize=8, loc="center right")
    bar = ax.figure.colorbar(plt.cm.ScalarMappable(norm=shade, cmap="viridis"), cax=ax.inset_axes([0.64, 0.88, 0.32, 0.04]),
                             orientation="horizontal")
    bar.set_label("ID = log2(2D/w) (bits)", fontsize=8)
    bar.ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)


def _hit_panel(ax, results: list[HumanTargetsResult], targets: HumanTargets) -> None:
    """Hit rate per condition, closed form (filled) and Monte Carlo (open), against the target band."""
    labels = [f"{r.distance:g}/{r.width:g}" for r in results[0].rows]
    x = np.arange(len(labels))
    ax.axhspan(*targets.hit_rate, color="C2", alpha=0.2, label=f"target {targets.hit_rate[0]:g}–{targets.hit_rate[1]:g}")
    for k, result in enumerate(results):
        color, offset = f"C{k}", 0.15 * (k - (len(results) - 1) / 2)
        ax.plot(x + offset, [r.hit_rate_closed_form for r in result.rows], _MARKERS[k], color=color, ms=6,
                label=f"{result.model_name}: closed form")
        ax.plot(x + offset, [r.hit_rate_monte_carlo for r in result.rows], _MARKERS[k], color=color, mfc="none", ms=9,
                label=f"{result.model_name}: Monte Carlo")
    ax.set_xticks(x, labels, rotation=60, fontsize=7)
    ax.set(xlabel="condition D/w (m)", ylabel="P(‖x − g‖ ≤ w) at MT", ylim=(-0.02, 1.02), title="hit rate")
    _legend_below(ax, 1.0, ncol=2)
    ax.grid(alpha=0.3)


def _asymmetry_panel(ax, results: list[HumanTargetsResult], targets: HumanTargets) -> None:
    """t_peak/MT against ID with the least-squares line, and the target's upper bound."""
    ax.axhline(targets.asymmetry_max, color="C3", ls="--", lw=1, label=f"target ≤ {targets.asymmetry_max:g}")
    for k, result in enumerate(results):
        ids = np.array([r.index_of_difficulty for r in result.rows])
        ratio = np.array([r.asymmetry for r in result.rows])
        ax.plot(ids, ratio, _MARKERS[k], color=f"C{k}", ms=6, label=f"{result.model_name}: slope {result.asymmetry_slope:+.3f}/bit")
        finite = np.isfinite(ratio)
        if np.isfinite(result.asymmetry_slope):
            line = np.array([ids.min(), ids.max()])
            ax.plot(line, np.nanmean(ratio[finite]) + result.asymmetry_slope * (line - ids[finite].mean()), color=f"C{k}", lw=1)
    ax.set(xlabel="ID = log2(2D/w) (bits)", ylabel="t_peak / MT", title="velocity peak timing")
    _legend_below(ax, 0.5)
    ax.grid(alpha=0.3)


def _fitts_panel(ax, results: list[HumanTargetsResult]) -> None:
    """MT against ID with the Fitts fit of each model."""
    for k, result in enumerate(results):
        ids = np.array([r.index_of_difficulty for r in result.rows])
        fit = result.fitts
        ax.plot(ids, [r.movement_time for r in result.rows], _MARKERS[k], color=f"C{k}", ms=6)
        line = np.array([ids.min(), ids.max()])
        ax.plot(line, fit.a + fit.b * line, color=f"C{k}", lw=1,
                label=f"{result.model_name}: MT = {fit.a:.3f} s + {1e3 * fit.b:.0f} ms/bit · ID, R² = {fit.r2:.3f}")
    ax.set(xlabel="ID = log2(2D/w) (bits)", ylabel="MT (s)", title="Fitts' law")
    _legend_below(ax, 0.5)
    ax.grid(alpha=0.3)


def _legend_below(ax, gap: float, ncol: int = 1) -> None:
    """Legend centred below ax, gap inches under the axes (clear of tick labels and axis label)."""
    below = ax.transAxes + ScaledTranslation(0.0, -gap, ax.figure.dpi_scale_trans)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, ncol=ncol)
