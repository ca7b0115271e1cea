"""The synchronisation task's targets, checked per person and goal on a comparison of robot policies.

For one candidate robot (``forecast`` by default) and every person–goal pair of
:func:`comanip.simulation.policy_comparison.compare_with_people`'s results, each target is met or not:

- **lightest**: the candidate's mean RMS force change (the person's force beyond holding the object) below every
  other policy's, the passive and admittance robots included;
- **guiding force**: its mean peak force change within the force people use to guide a partner through a held
  contact (``guiding_force``: 10–30 N, Sawers et al. 2017, :data:`comanip.demo.GUIDING_FORCE_N`); asked of the
  people ``guiding_people`` names;
- **arriving together**: the median over trials of |robot's height arrival − person's horizontal arrival| / MT at
  most :data:`IN_STEP_MT`;
- **peaks together**: the same for the lag between their speed peaks;
- **height at arrival**: the median height error at the person's arrival at most :data:`HEIGHT_TOLERANCE_M`.

A target holds over the pairs when the share of pairs meeting it is at least its required share (:data:`REQUIRED`).
"""

from __future__ import annotations

import numpy as np

#: Largest |lag| / MT (dimensionless) between the robot's and the person's arrivals or speed peaks in step.
IN_STEP_MT = 0.05
#: Largest height error at the person's arrival (m).
HEIGHT_TOLERANCE_M = 0.005

#: target -> (what it asks, the share of the pairs it is asked of that must meet it)
REQUIRED = {
    "lightest": ("RMS force beyond holding below every other robot's", 0.9),
    "guiding_force": ("peak force beyond holding within the guiding force (10–30 N)", 1.0),
    "arriving_together": ("|height arrival − horizontal arrival| ≤ 0.05 MT (median)", 0.9),
    "peaks_together": ("|height speed peak − horizontal speed peak| ≤ 0.05 MT (median)", 0.9),
    "height_at_arrival": ("height error at the person's arrival ≤ 5 mm (median)", 1.0),
}


def _values(trials, key: str) -> np.ndarray:
    values = np.array([trial.metrics[key] for trial in trials], dtype=float)
    return values[np.isfinite(values)]


def _mean(trials, key: str) -> float:
    values = _values(trials, key)
    return float(np.mean(values)) if len(values) else float("nan")


def _median_abs(trials, key: str) -> float:
    values = _values(trials, key)
    return float(np.median(np.abs(values))) if len(values) else float("nan")


def target_rows(results: dict, guiding_force: tuple[float, float], candidate: str = "forecast",
                guiding_people=None) -> list[dict]:
    """One row per person and goal of results {person: {goal: {policy: trials}}}: the candidate's values (mean RMS
    and peak force change, N; median |arrival lag| and |peak lag| / MT; median height error at arrival, m), the
    lightest other policy and its mean, and per target True/False (None where it is not asked: guiding force of a
    person outside ``guiding_people``, None: every person). guiding_force: (low, high) N."""
    rows = []
    for person, by_goal in results.items():
        for goal, by_policy in by_goal.items():
            if candidate not in by_policy:
                raise ValueError(f"the results of {person!r} at {goal!r} have no {candidate!r} trials")
            mine = by_policy[candidate]
            others = {name: _mean(trials, "rms_force_change_N") for name, trials in by_policy.items() if name != candidate}
            lightest = min(others, key=others.get) if others else None
            row = {"person": person, "goal": goal, "trials": len(mine),
                   "rms_force_change_N": _mean(mine, "rms_force_change_N"),
                   "peak_force_change_N": _mean(mine, "peak_force_change_N"),
                   "arrival_lag_mt": _median_abs(mine, "arrival_lag_mt"), "peak_lag_mt": _median_abs(mine, "peak_lag_mt"),
                   "height_error_at_arrival_m": float(np.median(_values(mine, "height_error_at_arrival_m")))
                   if len(_values(mine, "height_error_at_arrival_m")) else float("nan"),
                   "lightest_other": lightest, "lightest_other_N": others.get(lightest, float("nan"))}
            low, high = guiding_force
            asked = guiding_people is None or person in guiding_people
            row["lightest"] = bool(others) and all(row["rms_force_change_N"] < value for value in others.values())
            row["guiding_force"] = bool(low <= row["peak_force_change_N"] <= high) if asked else None
            row["arriving_together"] = bool(row["arrival_lag_mt"] <= IN_STEP_MT)
            row["peaks_together"] = bool(row["peak_lag_mt"] <= IN_STEP_MT)
            row["height_at_arrival"] = bool(row["height_error_at_arrival_m"] <= HEIGHT_TOLERANCE_M)
            rows.append(row)
    return rows


def target_summary(rows: list[dict]) -> dict:
    """target -> (pairs meeting it, pairs it is asked of, whether the required share is met)."""
    summary = {}
    for target, (_, share) in REQUIRED.items():
        asked = [row[target] for row in rows if row[target] is not None]
        met = sum(asked)
        summary[target] = (met, len(asked), bool(asked) and met >= share * len(asked))
    return summary


def targets_table(rows: list[dict]) -> str:
    """The targets as a markdown table: what each asks, the pairs meeting it and whether it holds."""
    lines = ["| target | required share of pairs | pairs meeting it | met? |", "|---|---|---|---|"]
    for target, (met, asked, holds) in target_summary(rows).items():
        what, share = REQUIRED[target]
        lines.append(f"| {what} | {share:.0%} | {met} of {asked} | {'yes' if holds else '**no**'} |")
    return "\n".join(lines) + "\n"


def robots_table(results: dict, guiding_force: tuple[float, float], guiding_people=None) -> str:
    """Every policy of results as the candidate in turn: per target the pairs meeting it, as a markdown table (what
    each robot would score on the targets the candidate is held to)."""
    policies = list(next(iter(next(iter(results.values())).values())))
    headings = ["robot"] + [REQUIRED[target][0] for target in REQUIRED]
    lines = ["| " + " | ".join(headings) + " |", "|" + "---|" * len(headings)]
    for name in policies:
        summary = target_summary(target_rows(results, guiding_force, name, guiding_people))
        lines.append("| " + " | ".join([name] + [f"{met} of {asked}" for met, asked, _ in summary.values()]) + " |")
    return "\n".join(lines) + "\n"


def pairs_table(rows: list[dict]) -> str:
    """Per person and goal, the candidate's values and each target's verdict, as a markdown table."""
    headings = ["person", "goal", "n", "RMS force change (N)", "lightest other robot (N)", "peak force change (N)",
                "|arrival lag| / MT", "|peak lag| / MT", "height error at arrival (mm)"]
    lines = ["| " + " | ".join(headings) + " |", "|" + "---|" * len(headings)]

    def mark(value: str, ok) -> str:
        return value if ok is None or ok else f"**{value}**"

    for row in rows:
        cells = [row["person"], row["goal"], str(row["trials"]),
                 mark(f"{row['rms_force_change_N']:.2f}", row["lightest"]),
                 f"{row['lightest_other']} {row['lightest_other_N']:.2f}",
                 mark(f"{row['peak_force_change_N']:.1f}", row["guiding_force"]),
                 mark(f"{row['arrival_lag_mt']:.3f}", row["arriving_together"]),
                 mark(f"{row['peak_lag_mt']:.3f}", row["peaks_together"]),
                 mark(f"{1e3 * row['height_error_at_arrival_m']:.1f}", row["height_at_arrival"])]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
