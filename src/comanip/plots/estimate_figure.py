"""Figures of goal estimation: the observed prefix, the predicted remainder and the estimated goal; and the
posterior over candidate goals as observations arrive."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle

from comanip.planning.plan import Plan
from comanip.plots.figure_file import save_figure

_AXES = "xyz"


def plot_estimate(plan: Plan, path: str | Path, observed_points=None, observed_times=None, true_goal=None,
                  title: str | None = None) -> Path:
    """Save a three-panel PNG of a goal estimate (a GoalEstimate from :func:`comanip.estimate_goal`).

    Panels: the task-space path (first two axes), each axis against time, and the speed. The predicted
    trajectory is solid up to the observed step (the prefix the estimate reproduces) and dashed after it
    (the predicted remainder, with ±2σ circles on the path).

    Args:
        plan: the estimate (its observed step, prior goal and method are drawn).
        path: PNG file to write.
        observed_points: measured end-effector positions (K, d), m, drawn as dots (e.g. a CSV's rows).
        observed_times: their times (K,), s.
        true_goal: the goal actually reached (d,), m, when known (simulations).
    """
    n_o = plan.observed_step
    x, t, d = plan.ee_mean, plan.t, plan.ee_mean.shape[1]
    fig, (ax_path, ax_pos, ax_speed) = plt.subplots(1, 3, figsize=(14, 4.3))

    _draw_path(ax_path, plan, observed_points, true_goal)
    goal = np.asarray(plan.goal)

    for k in range(d):
        ax_pos.plot(t[: n_o + 1], x[: n_o + 1, k], "-", color=f"C{k}", lw=2)
        ax_pos.plot(t[n_o:], x[n_o:, k], "--", color=f"C{k}", label=_AXES[k] if k < 3 else str(k))
        ax_pos.axhline(goal[k], color=f"C{k}", lw=0.6, alpha=0.5)
        if observed_points is not None and observed_times is not None:
            ax_pos.plot(observed_times, np.atleast_2d(observed_points)[:, k], ".", color="k", ms=5)
    ax_pos.axvline(plan.t[n_o], color="0.5", lw=0.8)
    ax_pos.set(xlabel="t (s)", ylabel="position (m)", title="position (thin: estimated goal)")
    ax_pos.legend(fontsize=8)

    speed = plan.ee_speed
    ax_speed.plot(t[: n_o + 1], speed[: n_o + 1], "-", color="C0", lw=2, label="observed prefix (model)")
    ax_speed.plot(t[n_o:], speed[n_o:], "--", color="C1", label="predicted remainder")
    ax_speed.axvline(plan.t[n_o], color="0.5", lw=0.8, label="observation")
    ax_speed.set(xlabel="t (s)", ylabel="speed (m/s)", title="end-effector speed")
    ax_speed.legend(fontsize=8)

    method = plan.method
    return save_figure(fig, path, title or f"{plan.model_name} goal estimate ({method}): goal {np.round(goal, 3).tolist()} m, "
                                           f"{plan.status}, {1e3 * plan.solve_time:.0f} ms")


def _draw_path(ax_path, plan: Plan, observed_points, true_goal) -> None:
    """The path panel of :func:`plot_estimate`: the observed prefix and the predicted remainder with its ±2σ
    circles, the estimated goal, the prior and true goals and the observations."""
    n_o = plan.observed_step
    x, d = plan.ee_mean, plan.ee_mean.shape[1]
    y = x[:, 1] if d > 1 else np.zeros(len(x))
    ax_path.plot(x[: n_o + 1, 0], y[: n_o + 1], "-", color="C0", lw=2, label="observed prefix (model)")
    ax_path.plot(x[n_o:, 0], y[n_o:], "--", color="C1", lw=1.5, label="predicted remainder")
    drawn = None
    for i in range(n_o, len(x)):
        cov = plan.ee_cov[i][:2, :2] if d > 1 else plan.ee_cov[i][:1, :1]
        radius = 2 * float(np.sqrt(np.max(np.linalg.eigvalsh(cov))))
        # one circle per stretch of path, not a stack of them where the hand dwells near the goal
        if drawn is None or np.hypot(x[i, 0] - drawn[0], y[i] - drawn[1]) > max(radius, 0.1 * plan.width):
            ax_path.add_patch(Circle((x[i, 0], y[i]), radius, fill=False, color="C1", alpha=0.35))
            drawn = (x[i, 0], y[i])
    goal = np.asarray(plan.goal)
    goal_y = goal[1] if d > 1 else 0.0
    ax_path.add_patch(Circle((goal[0], goal_y), plan.width, color="C3", alpha=0.2))
    ax_path.plot(goal[0], goal_y, "*", color="C3", ms=14, label="estimated goal (±w)")
    prior = plan.prior_goal
    if prior is not None:
        ax_path.plot(prior[0], prior[1] if d > 1 else 0.0, "x", color="k", ms=9, mew=2, label="prior goal")
    if true_goal is not None:
        ax_path.plot(true_goal[0], true_goal[1] if d > 1 else 0.0, "o", mfc="none", color="C2", ms=11, mew=2, label="true goal")
    if observed_points is not None:
        points = np.atleast_2d(observed_points)
        ax_path.plot(points[:, 0], points[:, 1] if d > 1 else np.zeros(len(points)), ".", color="k", ms=6, label="observations")
    ax_path.plot(x[n_o, 0], y[n_o], "o", color="C0", ms=8, label=f"observed state (t = {plan.t[n_o]:.3g} s)")
    ax_path.set(xlabel="x (m)", ylabel="y (m)", title="path (±2σ on the remainder)")
    ax_path.axis("equal")
    ax_path.legend(fontsize=7, loc="best")


def plot_posterior(posterior, path: str | Path, title: str | None = None) -> Path:
    """Save a two-panel PNG of a :class:`comanip.estimation.GoalPosterior`: the candidates with their
    planned paths (line width by final probability), and each candidate's probability over the observations."""
    fig, (ax_map, ax_prob) = plt.subplots(1, 2, figsize=(11, 4.3))
    final = posterior.probabilities[-1]
    for c, (goal, plan) in enumerate(zip(posterior.candidates, posterior.plans)):
        x = plan.ee_mean
        y = x[:, 1] if x.shape[1] > 1 else np.zeros(len(x))
        goal_y = goal[1] if len(goal) > 1 else 0.0
        ax_map.plot(x[:, 0], y, "-", color=f"C{c}", lw=0.8 + 3 * final[c], alpha=0.8)
        ax_map.add_patch(Circle((goal[0], goal_y), posterior.width, color=f"C{c}", alpha=0.25))
        ax_map.annotate(f"{c}: P = {final[c]:.2f}", (goal[0], goal_y), fontsize=8)
    ax_map.set(xlabel="x (m)", ylabel="y (m)", title="candidates and their plans (line width: final P)")
    ax_map.axis("equal")
    for c in range(len(posterior.candidates)):
        ax_prob.plot(posterior.times, posterior.probabilities[:, c], "o-", color=f"C{c}", label=f"candidate {c}")
    ax_prob.set(xlabel="time of the latest observation (s)", ylabel="P(goal | observations so far)", ylim=(-0.02, 1.02),
                title="posterior as observations arrive")
    ax_prob.legend(fontsize=8)
    return save_figure(fig, path, title or f"goal posterior over {len(posterior.candidates)} candidates; entropy "
                                           f"{posterior.entropy[0]:.2f} → {posterior.entropy[-1]:.2f} nats")
