"""Figures of an arm's reaches (:mod:`comanip.analysis.arm_reaches`): hand speed profiles, joint positions and
velocities against their limits, and the hand's path in two projections."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle

from comanip.analysis.arm_reaches import ArmReach
from comanip.plots.figure_file import save_figure


def _colors(reaches: list[ArmReach]) -> np.ndarray:
    return plt.cm.tab10(np.arange(len(reaches)) % 10)


def _label(reach: ArmReach) -> str:
    return reach.label + ("" if reach.plan.success else f" ({reach.plan.status})")


def plot_arm_speed_profiles(reaches: list[ArmReach], path: str | Path, title: str = "") -> Path:
    """Save a PNG of the hand speed ||J(mu_q) mu_qdot|| (m/s) against time for every reach, with a dot at
    the peak and a dotted line at the movement time (docs/formulation.md §6)."""
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for color, reach in zip(_colors(reaches), reaches):
        plan, metrics = reach.plan, reach.metrics
        ax.plot(plan.t, plan.ee_speed, color=color, lw=2, label=_label(reach))
        ax.plot(metrics.t_peak, metrics.peak_speed, "o", color=color, ms=5)
        if metrics.settled:
            ax.axvline(metrics.movement_time, color=color, ls=":", lw=1.2)
    ax.plot([], [], "o", color="gray", ms=5, label="peak speed")
    ax.plot([], [], color="gray", ls=":", lw=1.2, label="movement time (speed < 5 % of peak)")
    ax.set(xlabel="t (s)", ylabel="hand speed (m/s)", xlim=(0, reaches[0].plan.t[-1]))
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=8, title="goal offset from the ready pose", title_fontsize=8)
    ax.grid(alpha=0.3)
    return save_figure(fig, path, title or "hand speed profiles")


def plot_joint_trajectories(reaches: list[ArmReach], lower: np.ndarray, upper: np.ndarray, velocity: bool,
                            path: str | Path, title: str = "") -> Path:
    """Save a PNG with one panel per joint: the planned mean joint positions (rad; velocity=False) or
    velocities (rad/s; velocity=True) of every reach against time, the limits lower, upper (n,) dashed.

    Position panels are zoomed on the motion (the Panda's ranges are about 6 rad wide and a reach moves a
    joint a few tenths), so a limit shows only when the motion comes near it; its value is printed in the
    panel's title either way. Velocity panels show the full ±limit.
    """
    n = len(lower)
    columns = 4
    rows = -(-n // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(3.4 * columns, 2.7 * rows), sharex=True)
    axes = axes.ravel()
    unit = "rad/s" if velocity else "rad"
    for j in range(n):
        ax = axes[j]
        curves = [reach.plan.mean[:, n + j] if velocity else reach.plan.mean[:, j] for reach in reaches]
        for color, reach, curve in zip(_colors(reaches), reaches, curves):
            ax.plot(reach.plan.t, curve, color=color, lw=1.5, label=_label(reach))
        for limit in (lower[j], upper[j]):
            ax.axhline(limit, color="k", ls="--", lw=1)
        if velocity:
            ax.set_ylim(1.15 * lower[j], 1.15 * upper[j])
        else:
            low, high = min(c.min() for c in curves), max(c.max() for c in curves)
            pad = max(0.1, 0.25 * (high - low))
            ax.set_ylim(max(low - pad, lower[j] - 0.05), min(high + pad, upper[j] + 0.05))
        ax.set_title(f"joint {j + 1} (limits {lower[j]:.2f} … {upper[j]:.2f} {unit})", fontsize=9)
        ax.grid(alpha=0.3)
        if j % columns == 0:
            ax.set_ylabel(("qdot" if velocity else "q") + f" ({unit})")
        if j >= n - columns:
            ax.set_xlabel("t (s)")
            ax.xaxis.set_tick_params(labelbottom=True)
    legend_ax = axes[n] if len(axes) > n else axes[-1]
    for extra in axes[n:]:
        extra.axis("off")
    handles, labels = axes[0].get_legend_handles_labels()
    handles.append(plt.Line2D([], [], color="k", ls="--", lw=1))
    labels.append("joint limit")
    legend_ax.legend(handles, labels, fontsize=8, loc="center", title="goal offset", title_fontsize=8)
    kind = "velocities" if velocity else "positions"
    return save_figure(fig, path, title or f"joint {kind} (plan means)")


def plot_arm_paths(reaches: list[ArmReach], path: str | Path, title: str = "") -> Path:
    """Save a two-panel PNG of the mean hand paths seen from above (x–y) and from the side (x–z), m, with
    each goal drawn as a circle of radius w and the start as a star."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.2))
    for ax, (a, b) in zip(axes, ((0, 1), (0, 2))):
        for color, reach in zip(_colors(reaches), reaches):
            plan = reach.plan
            x = plan.ee_mean
            ax.plot(x[:, a], x[:, b], ".-", color=color, ms=3, lw=1.2, label=_label(reach))
            ax.add_patch(Circle((plan.goal[a], plan.goal[b]), plan.width, color=color, alpha=0.2))
            ax.plot(plan.goal[a], plan.goal[b], "+", color=color, ms=10, mew=2)
        start = reaches[0].plan.ee_mean[0]
        ax.plot(start[a], start[b], "k*", ms=12, label="start (ready pose)")
        ax.set(xlabel=f"{'xyz'[a]} (m)", ylabel=f"{'xyz'[b]} (m)",
               title="from above (x–y)" if b == 1 else "from the side (x–z)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    axes[0].plot([], [], "+", color="gray", ms=10, mew=2, label="goal")
    axes[0].plot([], [], "o", color="gray", alpha=0.3, ms=10, label="goal width w (projected)")
    axes[0].legend(fontsize=8, loc="best")
    return save_figure(fig, path, title or "hand paths (plan means)")
