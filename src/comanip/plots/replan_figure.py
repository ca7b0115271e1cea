"""Figure of a reach replanned in closed loop: every cycle's time against the control period, and the hand's speed
beside the loop replanned to convergence."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from comanip.execution.receding_horizon import Execution
from comanip.plots.figure_file import save_figure


def plot_replan(run: Execution, converged: Execution, path: str | Path, title: str = "") -> Path:
    """Save a two-panel PNG: each cycle's time from the state to the command and its preparation of the next (ms)
    over the loop's time, the period dashed; the hand's speed (m/s) of ``run`` and of the ``converged`` loop."""
    fig, (ax_time, ax_speed) = plt.subplots(1, 2, figsize=(11, 4))
    period_ms = 1e3 * float(run.t[1] - run.t[0])
    ax_time.plot(run.t[1:-1], 1e3 * run.replan_times[1:], ".", ms=3, label="state → command")
    ax_time.plot(run.t[1:-2], 1e3 * run.preparation_times[1:-1], ".", ms=3, alpha=0.6, label="preparation of the next cycle")
    ax_time.axhline(period_ms, color="k", ls="--", lw=1, label=f"period ({period_ms:g} ms)")
    ax_time.set(xlabel="t (s)", ylabel="wall time (ms)", title="cycle times (the first plan left out)")
    ax_time.legend(fontsize=8)
    ax_speed.plot(run.t, run.ee_speed, label="real-time loop")
    ax_speed.plot(converged.t, converged.ee_speed, "--", label="converged every cycle")
    jumps = np.flatnonzero(np.any(np.diff(run.goals, axis=0) != 0, axis=1))
    for k in jumps:
        ax_speed.axvline(run.t[k + 1], color="grey", lw=1, ls=":")
    ax_speed.set(xlabel="t (s)", ylabel="hand speed (m/s)", title="executed reach" + (" (goal jump dotted)" if len(jumps) else ""))
    ax_speed.legend(fontsize=8)
    return save_figure(fig, path, title)
