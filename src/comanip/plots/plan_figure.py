"""Figure of one plan: path with its uncertainty, speed and spread over time."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle

from comanip.planning.plan import Plan


def plot_plan(plan: Plan, path: str | Path, title: str | None = None) -> Path:
    """Save a three-panel PNG: task-space path (first two axes) with ±2σ circles, speed, per-axis std."""
    fig, (ax_path, ax_speed, ax_std) = plt.subplots(1, 3, figsize=(13, 4))
    x = plan.ee_mean
    ax_path.plot(x[:, 0], x[:, 1] if x.shape[1] > 1 else np.zeros(len(x)), ".-", label="mean")
    for i in range(0, len(x), max(1, len(x) // 10)):
        radius = 2 * float(np.sqrt(np.max(np.linalg.eigvalsh(plan.ee_cov[i][:2, :2]))))
        ax_path.add_patch(Circle(x[i, :2], radius, fill=False, alpha=0.4))
    goal = plan.goal
    ax_path.add_patch(Circle((goal[0], goal[1] if len(goal) > 1 else 0.0), plan.width, color="g", alpha=0.3, label="goal (w)"))
    ax_path.set(xlabel="x (m)", ylabel="y (m)", title="path, ±2σ")
    ax_path.axis("equal")
    ax_path.legend()
    ax_speed.plot(plan.t, plan.ee_speed)
    ax_speed.set(xlabel="t (s)", ylabel="speed (m/s)", title="end-effector speed")
    for k, axis in enumerate("xyz"[: x.shape[1]]):
        ax_std.plot(plan.t, 1e3 * plan.ee_std[:, k], label=axis)
    ax_std.set(xlabel="t (s)", ylabel="std (mm)", title="end-effector spread")
    ax_std.legend()
    fig.suptitle(title or f"{plan.model_name}: {plan.summary()}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
