"""Figures of a fit: recorded against predicted hand position and speed per condition (recordings fit), or
given against predicted movement time over the index of difficulty (movement-time fit)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.analysis.fitts import index_of_difficulty
from comanip.fitting.fit_result import FitResult
from comanip.plots.figure_file import save_figure

MAX_CONDITIONS = 8
"""At most this many conditions get a column of their own."""


def plot_fit(result: FitResult, path: str | Path) -> Path:
    """Save the figure of a fit as a PNG: per-condition curves when the result has them, the timing per condition for a
    timing fit, else movement times."""
    if result.curves:
        return _plot_recordings_fit(result, path)
    if result.conditions and "peak_fraction_predicted" in result.conditions[0]:
        return _plot_timing_fit(result, path)
    return _plot_movement_time_fit(result, path)


def _plot_recordings_fit(result: FitResult, path: str | Path) -> Path:
    """Two rows per condition column: position per axis over time (recorded mean solid, predicted mean dashed
    with a ±2σ band), and speed (recorded mean, predicted) with both movement times marked."""
    shown = list(zip(result.conditions, result.curves))[:MAX_CONDITIONS]
    fig, axes = plt.subplots(2, len(shown), figsize=(3.6 * len(shown) + 0.8, 6.2), squeeze=False, sharex=True)
    for column, (row, curve) in enumerate(shown):
        ax_x, ax_v = axes[0, column], axes[1, column]
        for a in range(curve["predicted_mean"].shape[1]):
            mean, std = curve["predicted_mean"][:, a], curve["predicted_std"][:, a]
            ax_x.fill_between(curve["t"], mean - 2 * std, mean + 2 * std, color=f"C{a}", alpha=0.15, lw=0)
            ax_x.plot(curve["t"], mean, "--", color=f"C{a}", lw=1.5, label=f"{'xyz'[a]} predicted ±2σ")
            ax_x.plot(curve["recorded_t"], curve["recorded_mean"][:, a], "-", color=f"C{a}", lw=1.2, label=f"{'xyz'[a]} recorded mean")
        ax_v.plot(curve["t"], curve["predicted_speed"], "--", color="k", lw=1.5, label="predicted")
        ax_v.plot(curve["recorded_t"], curve["recorded_speed"], "-", color="C3", lw=1.2, label="recorded mean")
        for mt, color in ((row["mt_predicted_s"], "k"), (row["mt_recorded_s"], "C3")):
            if mt is not None and np.isfinite(mt):
                ax_v.axvline(mt, color=color, ls=":", lw=1)
        ax_x.set_title(f"goal {np.round(row['goal'], 3).tolist()} m, w = {row['width']:g} m\n{row['trials']} trials, "
                       f"RMS error {1e3 * row['rms_error_m']:.1f} mm", fontsize=8)
        ax_v.set_xlabel("t (s)")
    axes[0, 0].set_ylabel("hand position (m)")
    axes[1, 0].set_ylabel("hand speed (m/s); MT dotted")
    axes[0, 0].legend(fontsize=6)
    axes[1, 0].legend(fontsize=7)
    more = f" (first {MAX_CONDITIONS} of {len(result.conditions)} conditions)" if len(result.conditions) > MAX_CONDITIONS else ""
    return save_figure(fig, path, f"{result.model.name}: {_values(result)}{more}")


def _plot_movement_time_fit(result: FitResult, path: str | Path) -> Path:
    """Given and predicted MT against the Fitts index of difficulty log2(2D/w)."""
    rows = result.conditions
    ids = index_of_difficulty([r["distance_m"] for r in rows], [r["width_m"] for r in rows])
    predicted = np.array([np.nan if r["mt_predicted_s"] is None else r["mt_predicted_s"] for r in rows], dtype=float)
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ax.plot(ids, [r["mt_recorded_s"] for r in rows], "o", color="C3", label="given")
    ax.plot(ids, predicted, "x", color="k", ms=8, label="predicted by the fitted model")
    ax.set_xlabel("index of difficulty log2(2D/w) (bits)")
    ax.set_ylabel("movement time (s)")
    ax.legend(fontsize=8)
    return save_figure(fig, path, f"{result.model.name}: {_values(result)}")


def _plot_timing_fit(result: FitResult, path: str | Path) -> Path:
    """Recorded (the trials' mean reach, ±2 standard errors) and predicted MT and t_peak/MT, per condition."""
    rows = result.conditions
    index = np.arange(len(rows))
    fig, axes = plt.subplots(1, 2, figsize=(8.5, 3.8))
    for ax, key, unit, label in ((axes[0], "mt", "_s", "movement time (s)"), (axes[1], "peak_fraction", "", "t_peak / MT")):
        ax.errorbar(index, [r[f"{key}_recorded{unit}"] for r in rows], yerr=[2 * r[f"{key}_recorded_se{unit}"] for r in rows],
                    fmt="o", color="C3", capsize=3, label="recorded mean reach ±2 SE")
        ax.plot(index, [np.nan if r[f"{key}_predicted{unit}"] is None else r[f"{key}_predicted{unit}"] for r in rows],
                "x", color="k", ms=8, label="fitted model's mean closed-loop reach")
        ax.set_xticks(index, [f"{r['condition']}\n{r['trials']} trials" for r in rows], fontsize=7)
        ax.set_xlabel("condition")
        ax.set_ylabel(label)
    axes[0].legend(fontsize=7)
    return save_figure(fig, path, f"{result.model.name}: {_values(result)}")


def _values(result: FitResult) -> str:
    return ", ".join(f"{name} = {value:.3g}" for name, value in result.values.items()) + f" ({result.status})"
