"""Paper Fig. 8 layout: the handover over distance to the goal, one colour per goal, transition marked."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.multicomponent.handover import HandoverSchedule
from comanip.planning.plan import Plan


def plot_handover(plans: list[Plan], schedules: list[HandoverSchedule], path: str | Path) -> Path:
    """Save a three-row PNG over distance to the goal (m, decreasing to the right): the predicted spread of the
    hand about the plan (std, mm), the rest-position speed (m/s) and the stiffness (N/m); a dashed line per
    goal at the predicted transition distance, with its ±1σ band."""
    fig, (ax_std, ax_speed, ax_k) = plt.subplots(3, 1, figsize=(7.5, 8), sharex=True)
    colours = plt.cm.tab10(np.arange(len(plans)))
    for colour, plan, schedule in zip(colours, plans, schedules):
        label = f"D = {schedule.goal_distance:.2f} m, w = {1e3 * schedule.width:g} mm"
        plan_distance = np.linalg.norm(plan.ee_mean - schedule.goal, axis=1)
        spread = np.sqrt(np.trace(plan.ee_cov, axis1=1, axis2=2))
        ax_std.plot(plan_distance, 1e3 * spread, ".-", color=colour, label=label)
        ax_speed.plot(schedule.distance_to_goal, schedule.rest_speed, color=colour)
        ax_k.plot(schedule.distance_to_goal, schedule.stiffness, color=colour)
        for ax in (ax_std, ax_speed, ax_k):
            T, s = schedule.transition_distance, schedule.transition_distance_std
            ax.axvline(T, color=colour, ls="--", lw=1)
            ax.axvspan(T - s, T + s, color=colour, alpha=0.12)
    ax_std.set(ylabel="hand spread about the plan (mm)", title="authority handover: robot leads, person finishes")
    ax_std.legend(fontsize=8)
    ax_speed.set(ylabel="rest-position speed (m/s)")
    ramp = schedules[0].ramp_time if schedules else 0.0
    ax_k.set(ylabel="translational stiffness (N/m)", xlabel="distance to goal (m)")
    ax_k.text(0.02, 0.1, f"ramp {1e3 * ramp:.0f} ms (raised cosine); dashed: predicted transition",
              transform=ax_k.transAxes, fontsize=8)
    ax_k.invert_xaxis()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
