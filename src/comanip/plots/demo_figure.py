"""Figures of the demo (:mod:`comanip.demo`): the online prediction of a recorded person's goal, and the robot beside
a person guiding the handle."""

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


def plot_co_manipulation(record, forecasts, observation_time: float, movement_time: float, guiding_force, names: dict,
                         path: str | Path, title: str = "") -> Path:
    """Four panels of one sync trial, titled with ``names`` (the report's names: keys ``goal``, ``path``,
    ``force``): the distance of the robot's goal estimate from the person's goal over time; the force between the
    person and the handle with the holding force and the ``guiding_force`` range (low, high) N that people apply;
    the predicted path of the hand at each forecast against the hand, from above; and each forecast's distance
    from the hand over time.

    record: the trial's :class:`~comanip.simulation.TrialRecord`; forecasts: :class:`comanip.demo.Forecast` s;
    observation_time, movement_time: t_o and MT (s)."""
    fig, ((ax_goal, ax_force), (ax_top, ax_path)) = plt.subplots(2, 2, figsize=(12, 8.2))
    colors = plt.cm.viridis(np.linspace(0.1, 0.8, len(forecasts)))
    t = record.t
    goal_error = np.linalg.norm(record.goal_estimate - record.goal, axis=1)
    ax_goal.plot(t, 100 * goal_error, "k-", lw=1.5, label="|goal estimate − person's goal|")
    force = np.linalg.norm(record.person_force, axis=1)
    change = np.linalg.norm(record.person_force - record.person_force[0], axis=1)
    low, high = guiding_force
    ax_force.axhspan(low, high, color="C2", alpha=0.15, label=f"people guiding a partner: {low:.0f}–{high:.0f} N")
    ax_force.plot(t, force, "k-", lw=1.5, label="force |F|")
    ax_force.plot(t, change, "C0--", lw=1.2, label="force beyond holding the object |F − F(0)|")
    ax_force.axhline(force[0], color="0.5", lw=0.8, ls=":", label=f"holding the object at rest: {force[0]:.1f} N")
    ax_top.plot(record.position[:, 0], record.position[:, 1], "k-", lw=2.0, label="the hand (handle)")
    ax_top.plot(*record.goal[:2], "r*", ms=14, label="the person's goal")
    for color, forecast in zip(colors, forecasts):
        label = f"forecast at {forecast.made_at:.2f} s"
        ax_top.plot(forecast.position[:, 0], forecast.position[:, 1], "--", color=color, lw=1.5, label=label)
        ax_top.plot(*forecast.hand[0, :2], "o", color=color, ms=6)
        ax_top.plot(*forecast.goal[:2], "x", color=color, ms=9, mew=2)
        ax_path.plot(forecast.t, 100 * forecast.error, color=color, lw=1.5, label=label)
        for ax in (ax_goal, ax_force):
            ax.axvline(forecast.made_at, color=color, lw=0.8, ls=":")
    for ax in (ax_goal, ax_force, ax_path):
        ax.axvline(observation_time, color="0.4", lw=0.8, ls="-.")
        ax.axvline(movement_time, color="0.4", lw=0.8, ls="--")
        ax.set_xlim(0.0, movement_time * 1.3)
        ax.grid(alpha=0.3)
    ax_goal.text(observation_time, 0.97, " t_o: the robot leads", transform=ax_goal.get_xaxis_transform(), fontsize=8,
                 va="top", color="0.4")
    ax_goal.text(movement_time, 0.97, " MT", transform=ax_goal.get_xaxis_transform(), fontsize=8, va="top", color="0.4")
    ax_goal.set(xlabel="t (s)", ylabel="cm", title=names["goal"])
    ax_force.set(xlabel="t (s)", ylabel="N", title=names["force"], ylim=(0, max(high * 1.3, 1.1 * float(force.max()))))
    ax_top.set(xlabel="x (m)", ylabel="y (m)", title=f"{names['path']}, from above\n(o: the hand and x: the goal "
                                                      f"estimate when the forecast is made)")
    ax_top.axis("equal")
    ax_path.set(xlabel="t (s)", ylabel="cm", title=f"{names['path']}:\nthe forecast's distance from the hand")
    for ax in (ax_goal, ax_force, ax_top, ax_path):
        ax.legend(fontsize=8, loc="best")
    return save_figure(fig, path, title)
