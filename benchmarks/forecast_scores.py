"""Scores of the online estimator's forecast of the hand (where it will be 0.1, 0.2 and 0.3 s on), beside kinematic
forecasters given the same inputs, for ``real_people.py``.

From the update at 25 % and 50 % of a movement's MT, each forecaster's position at +LEADS s is compared with the
recorded hand's (held at its endpoint after the movement ends): error / D. The kinematic forecasters get the
hand's position and velocity of that update and the acceleration from its last velocities
(:func:`comanip.estimation.forecast.path_baselines.recent_acceleration`); minimum jerk also gets the estimate's own goal and
stop time. The forecast's 95 % region (its covariance) is checked on the recorded position.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

from comanip.estimation.forecast import path_baselines as kinematic
from comanip.estimation.forecast.hand_forecast import continued_reach

LEADS = (0.1, 0.2, 0.3)
FROM = (0.25, 0.5)
KINEMATIC = ("hand stays", "constant velocity", "constant acceleration", "minimum jerk to the estimate's goal and stop")
GIVEN_THE_END = ("the forecast given the recorded endpoint and stop", "minimum jerk given the recorded endpoint and stop")
"""What a perfect goal and stop would give each shape: not predictors, the ceiling of each."""


def holds(error: np.ndarray, covariance: np.ndarray) -> bool:
    """Whether the 95 % region of ``covariance`` (d, d) m² around an estimate holds a truth ``error`` (d,) m from it;
    a singular covariance's region (a point, or a flat ellipsoid) holds it only where the error lies in its span."""
    try:
        return bool(error @ np.linalg.solve(covariance, error) <= chi2.ppf(0.95, len(error)))
    except np.linalg.LinAlgError:
        flat = np.linalg.lstsq(covariance, error, rcond=None)[0]
        inside = np.allclose(covariance @ flat, error, atol=1e-12)
        return bool(inside and error @ flat <= chi2.ppf(0.95, len(error)))


def truth(recording, k: int) -> np.ndarray:
    """Where the recorded hand is at +LEADS s from its sample k (held at its endpoint after the end): (len(LEADS), d) m."""
    return np.array([recording.position_at(recording.t[k] + s) for s in LEADS])


def kinematic_paths(recording, k: int) -> dict[str, np.ndarray]:
    """The hand staying, constant velocity and constant acceleration from the recording's sample k, at +LEADS s:
    {forecaster: (len(LEADS), d) m}; the acceleration from the velocities up to k."""
    x, v = recording.position[k], recording.velocity[k]
    a = kinematic.recent_acceleration(recording.t[:k + 1], recording.velocity[:k + 1])
    return {"hand stays": kinematic.hand_stays(x, LEADS), "constant velocity": kinematic.constant_velocity(x, v, LEADS),
            "constant acceleration": kinematic.constant_acceleration(x, v, a, LEADS)}


def forecast_rows(trace, recording, name: str, estimator) -> list[dict]:
    """One row per (start fraction, lead, forecaster) for one movement; ``trace`` is [(t, estimate)] of every
    update of the online estimator ``name`` (an :class:`~comanip.OnlineGoalEstimator`, ``estimator``)."""
    D = recording.distance
    rows = []
    for start in FROM:
        k = recording.seen_until(start) - 1
        if k < 1 or k >= len(trace):
            continue
        t_now, estimate = trace[k]
        forecast = estimate.forecast
        if forecast is None:
            continue
        x, v = recording.position[k], recording.velocity[k]
        a = kinematic.recent_acceleration(recording.t[:k + 1], recording.velocity[:k + 1])
        lead = np.array(LEADS)
        recorded = truth(recording, k)
        predicted = forecast.at(t_now + lead)
        stop_in = forecast.stop_time - t_now
        paths = kinematic_paths(recording, k) | {
                 "minimum jerk to the estimate's goal and stop": kinematic.minimum_jerk_to(x, v, a, estimate.goal, stop_in, lead),
                 name: predicted.position,
                 GIVEN_THE_END[0]: continued_reach(estimator.family, estimator.start_position, t_now,
                                                   x, v, recording.end, np.zeros((len(x), len(x))), recording.end_time,
                                                   a).at(t_now + lead).position,
                 GIVEN_THE_END[1]: kinematic.minimum_jerk_to(x, v, a, recording.end, recording.end_time - t_now, lead)}
        for forecaster, path in paths.items():
            for i, s in enumerate(lead):
                error = path[i] - recorded[i]
                covered = holds(error, predicted.covariance[i]) if forecaster == name else None
                rows.append({"movement": recording.name, "forecaster": forecaster, "from": start, "lead_s": float(s),
                             "error": float(np.linalg.norm(error)) / D, "covered": covered})
    return rows


def forecast_markdown(rows, name: str) -> str:
    """Median error / D per forecaster, start fraction and lead, the forecast's coverage, and whether it is below
    every kinematic forecaster."""
    header = " | ".join(f"{int(100 * f)} % +{s:.1f} s" for f in FROM for s in LEADS)
    lines = ["Where the hand will be, error / D (median over movements), from 25 % and 50 % of MT:", "",
             f"| forecaster | {header} |", "|---|" + "---|" * (len(FROM) * len(LEADS))]
    medians = {}
    for forecaster in (*KINEMATIC, name):
        cells = []
        for f in FROM:
            for s in LEADS:
                errors = [r["error"] for r in rows if r["forecaster"] == forecaster and r["from"] == f and r["lead_s"] == s]
                medians[forecaster, f, s] = float(np.median(errors)) if errors else float("nan")
                cells.append(f"{medians[forecaster, f, s]:.3f}")
        label = f"**{forecaster}**" if forecaster == name else forecaster
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    below = [all(medians[name, f, s] < medians[k, f, s] for k in KINEMATIC) for f in FROM for s in LEADS]
    lines.append("| below every kinematic forecaster | " + " | ".join("yes" if b else "no" for b in below) + " |")
    cover = []
    for f in FROM:
        for s in LEADS:
            flags = [r["covered"] for r in rows if r["forecaster"] == name and r["from"] == f and r["lead_s"] == s]
            cover.append(f"{100 * np.mean(flags):.0f} %" if flags else "–")
    lines.append("| forecast's 95 % region holds the hand | " + " | ".join(cover) + " |")
    for forecaster in GIVEN_THE_END:
        lines.append(f"| {forecaster} | " + " | ".join(
            f"{np.median([r['error'] for r in rows if r['forecaster'] == forecaster and r['from'] == f and r['lead_s'] == s]):.3f}"
            for f in FROM for s in LEADS) + " |")
    return "\n".join(lines)


def forecast_figure(examples, path, title: str) -> None:
    """Recorded reaches (distance from the start along start → end, over time) with the forecast from 25 % and
    50 % of MT (mean and 95 % band) and constant velocity; ``examples`` is [(recording, trace)]."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(examples), figsize=(3.2 * len(examples), 3.2), squeeze=False)
    for ax, (recording, trace) in zip(axes[0], examples):
        start, end = recording.start, recording.end
        axis = (end - start) / recording.distance
        along = (recording.position - start) @ axis
        ax.plot(recording.t - recording.onset, along, color="k", lw=1.5, label="recorded hand")
        for fraction, color in zip(FROM, ("tab:blue", "tab:orange")):
            k = recording.seen_until(fraction) - 1
            if k < 1 or k >= len(trace) or trace[k][1].forecast is None:
                continue
            t_now, estimate = trace[k]
            times = t_now + np.linspace(0.0, max(LEADS), 31)
            ahead = estimate.forecast.at(times)
            mean = (ahead.position - start) @ axis
            spread = 1.96 * np.sqrt(np.einsum("i,kij,j->k", axis, ahead.covariance, axis))
            ax.plot(times - recording.onset, mean, color=color, label=f"forecast from {int(100 * fraction)} % of MT")
            ax.fill_between(times - recording.onset, mean - spread, mean + spread, color=color, alpha=0.15)
            straight = kinematic.constant_velocity(recording.position[k], recording.velocity[k], times - t_now)
            ax.plot(times - recording.onset, (straight - start) @ axis, color=color, ls=":", lw=1,
                    label=f"constant velocity from {int(100 * fraction)} %")
        ax.set_ylim(-0.1 * recording.distance, 1.6 * recording.distance)
        ax.set_xlabel("time since onset (s)")
        ax.set_title(recording.name.split("/")[-1], fontsize=8)
    axes[0, 0].set_ylabel("hand along start → end (m)")
    axes[0, 0].legend(fontsize=6, loc="lower right")
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
