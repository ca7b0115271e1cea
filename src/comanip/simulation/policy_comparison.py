"""Robot policies compared on the synchronisation scenario over the same trials and person seeds.

Every policy meets the same people: trial k of a goal uses seed + k whatever the robot does, so the
differences between policies are the robot's. Each measure (:mod:`comanip.simulation.measures`) is
summarised per goal and policy by its median and interquartile range over the trials.

>>> results = compare_sync_policies({"near": SyncSettings(goal="near", trials=20)}, list(POLICIES))
>>> rows = comparison_rows(results)
>>> write_comparison(rows, Path("out/sync_policies"))      # .csv and .md

The same policies also meet people who are not the model (:func:`compare_with_people`: a person at another
pace, or one whose intended path is a recorded movement; :class:`comanip.simulation.person.PersonParameters`),
summarised by :func:`people_rows` as the mean and standard deviation over the trials of the goal error and the
person's efforts (force change, work beyond holding), with the candidate policy's verdicts against the baselines.
"""

from __future__ import annotations

from typing import NamedTuple

import csv
from dataclasses import replace
from pathlib import Path

import numpy as np

from comanip.simulation.person import PersonParameters
from comanip.simulation.policies import POLICIES, check_policy
from comanip.simulation.report import summarise
from comanip.simulation.setup import ScenarioSetup
from comanip.simulation.sync_scenario import SyncSettings, SyncTrial, run_sync

#: The compared measures: key in the trial metrics -> (column heading, scale to the shown unit).
COMPARED = {
    "goal_error_first_m": ("goal error at t_o (mm)", 1e3),
    "goal_error_mean_m": ("goal error, mean t_o–MT (mm)", 1e3),
    "goal_error_final_m": ("goal error at the end (mm)", 1e3),
    "rms_force_change_N": ("RMS force change (N)", 1.0),
    "peak_force_change_N": ("peak force change (N)", 1.0),
    "rms_force_N": ("RMS force (N)", 1.0),
    "work_against_robot_J": ("work against robot (J)", 1.0),
    "person_work_J": ("person's work beyond holding (J)", 1.0),
    "sync_error_rms": ("sync error (% of reach)", 100.0),
    "arrival_lag_mt": ("height arrival − person's arrival (/ MT)", 1.0),
    "peak_lag_mt": ("height speed peak − person's (/ MT)", 1.0),
    "height_error_at_arrival_m": ("height error at the person's arrival (mm)", 1e3),
    "completion_time_s": ("completion (s)", 1.0),
    "final_error_m": ("placement error (mm)", 1e3),
}


def compare_sync_policies(settings_by_goal: dict[str, SyncSettings], policies, setup: ScenarioSetup | None = None,
                          progress: bool = False) -> dict[str, dict[str, list[SyncTrial]]]:
    """{goal label: {policy: trials}}: every policy (names of POLICIES) run on each goal's settings (their own
    policy field is replaced), sharing one setup (the solvers are built once)."""
    policies = [check_policy(name) for name in policies]
    if not settings_by_goal:
        raise ValueError("settings_by_goal must name at least one goal")
    setup = setup or ScenarioSetup(next(iter(settings_by_goal.values())))
    return {label: {name: run_sync(replace(settings, policy=name), setup, progress) for name in policies}
            for label, settings in settings_by_goal.items()}


def compare_with_people(settings_by_goal: dict[str, SyncSettings], people: dict[str, PersonParameters], policies,
                        setup: ScenarioSetup | None = None, progress: bool = False) -> dict[str, dict[str, dict[str, list[SyncTrial]]]]:
    """{person label: {goal label: {policy: trials}}}: :func:`compare_sync_policies` with each person's
    parameters in place of the settings' person, all sharing one setup."""
    if not people:
        raise ValueError("people must name at least one person")
    setup = setup or ScenarioSetup(next(iter(settings_by_goal.values())))
    return {person: compare_sync_policies({label: replace(settings, person=parameters) for label, settings in settings_by_goal.items()},
                                          policies, setup, progress)
            for person, parameters in people.items()}


#: The policy the people comparison's verdicts are about, and the one whose goal and forecast errors it must beat.
CANDIDATE, GOAL_ERROR_BASELINE = "forecast", "constant-velocity"

#: The robot's errors the people comparison sets against the baseline's: name -> key in the trial metrics (m).
ERRORS = {"goal_error": "goal_error_mean_m", "forecast_error": "forecast_error_mean_m"}

#: The person's efforts the people comparison reports: name -> (key in the trial metrics, heading, unit).
EFFORTS = {
    "force_change": ("rms_force_change_N", "RMS force change", "N"),
    "work": ("person_work_J", "person's work beyond holding", "J"),
    "peak_force": ("peak_force_change_N", "peak force change", "N"),
}


def people_rows(results: dict[str, dict[str, dict[str, list[SyncTrial]]]]) -> list[dict]:
    """One row per person and goal (results of :func:`compare_with_people`): the candidate's and the goal-error
    baseline's mean goal and forecast errors from t_o to MT (:data:`ERRORS`, mm) and every policy's efforts
    (:data:`EFFORTS`: RMS force change, N, the person's work beyond holding, J, and the peak force change, N), each as
    mean and standard deviation over the trials, with the verdicts: ``goal_error_below`` and
    ``forecast_error_below`` (candidate's mean below the baseline's) and, per effort,
    ``<effort>_above`` (the policies whose mean effort is below the candidate's); and, over the trials paired
    by seed (the same person for every policy), the candidate's goal and forecast errors minus the baseline's
    (``goal_error_difference_mm``, ``forecast_error_difference_mm``) and its effort minus each lighter policy's (``<effort>_excess_<policy>_<unit>``),
    as mean and standard error."""
    rows = []
    for person, by_goal in results.items():
        for goal, by_policy in by_goal.items():
            row = {"person": person, "goal": goal, "trials": len(next(iter(by_policy.values())))}
            for error, key in ERRORS.items():
                for name in (CANDIDATE, GOAL_ERROR_BASELINE):
                    if name in by_policy:
                        row[f"{error}_{name}_mm"] = _mean_std(by_policy[name], key, 1e3)
            for effort, (key, _, unit) in EFFORTS.items():
                for name, trials in by_policy.items():
                    row[f"{effort}_{name}_{unit}"] = _mean_std(trials, key, 1.0)
            if CANDIDATE in by_policy:
                mine = by_policy[CANDIDATE]
                if GOAL_ERROR_BASELINE in by_policy:
                    for error, key in ERRORS.items():
                        row[f"{error}_below"] = bool(row[f"{error}_{CANDIDATE}_mm"][0] < row[f"{error}_{GOAL_ERROR_BASELINE}_mm"][0])
                        row[f"{error}_difference_mm"] = _paired(mine, by_policy[GOAL_ERROR_BASELINE], key, 1e3)
                for effort, (key, _, unit) in EFFORTS.items():
                    row[f"{effort}_above"] = [name for name in by_policy if name != CANDIDATE
                                              and row[f"{effort}_{name}_{unit}"][0] < row[f"{effort}_{CANDIDATE}_{unit}"][0]]
                    for name in row[f"{effort}_above"]:
                        row[f"{effort}_excess_{name}_{unit}"] = _paired(mine, by_policy[name], key, 1.0)
            rows.append(row)
    return rows


def people_table(rows: list[dict], policies, effort: str = "force_change", goal_error: bool = True) -> str:
    """:func:`people_rows` as a markdown table: the goal errors (unless goal_error=False) and one effort of
    :data:`EFFORTS` per policy, cells 'mean ± std' over the trials, paired differences 'mean ± standard error',
    the verdicts last (each baseline with less effort followed by the candidate's paired excess over it)."""
    _, heading, unit = EFFORTS[effort]
    baselines = [name for name in policies if name != CANDIDATE]
    headings = ["person", "goal", "n"]
    if goal_error:
        for error in ERRORS:
            what = error.replace("_", " ")
            headings += [f"{what} t_o–MT, {CANDIDATE} (mm)", f"… {GOAL_ERROR_BASELINE} (mm)", "paired difference (mm)"]
    headings += [f"{heading}, {CANDIDATE} ({unit})"] + [f"… {name} ({unit})" for name in baselines]
    if goal_error:
        headings.append(f"{CANDIDATE} below {GOAL_ERROR_BASELINE}? (goal, forecast)")
    headings.append(f"baselines with less {heading} than {CANDIDATE}")
    lines = ["| " + " | ".join(headings) + " |", "|" + "---|" * len(headings)]
    for row in rows:
        cells = [row["person"], row["goal"], str(row["trials"])]
        if goal_error:
            for error in ERRORS:
                cells += [_pm(row.get(f"{error}_{name}_mm")) for name in (CANDIDATE, GOAL_ERROR_BASELINE)]
                cells.append(_pm(row.get(f"{error}_difference_mm"), signed=True))
        cells += [_pm(row.get(f"{effort}_{name}_{unit}")) for name in [CANDIDATE] + baselines]
        if goal_error:
            below = [row.get(f"{error}_below") for error in ERRORS]
            cells.append(", ".join("–" if b is None else "yes" if b else "**no**" for b in below))
        above = row.get(f"{effort}_above")
        cells.append("–" if above is None else "none" if not above else "**" + ", ".join(
            f"{name} ({_pm(row[f'{effort}_excess_{name}_{unit}'], signed=True)} {unit})" for name in above) + "**")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


class MeanStd(NamedTuple):
    """A measure over trials, in the shown unit."""

    mean: float
    std: float
    """Standard deviation (ddof 1; 0 for one trial)."""


class PairedDifference(NamedTuple):
    """A measure's difference between two policies over trials paired by person seed, in the shown unit."""

    mean: float
    standard_error: float


def _mean_std(trials: list[SyncTrial], key: str, scale: float) -> MeanStd:
    """(mean, standard deviation (ddof 1; 0 for one trial)) of a trial metric over the trials where it is
    finite, in the shown unit; (NaN, NaN) when none is."""
    values = np.array([trial.metrics[key] for trial in trials], dtype=float) * scale
    values = values[np.isfinite(values)]
    if not len(values):
        return MeanStd(float("nan"), float("nan"))
    return MeanStd(float(np.mean(values)), float(np.std(values, ddof=1)) if len(values) > 1 else 0.0)


def _paired(trials: list[SyncTrial], others: list[SyncTrial], key: str, scale: float) -> PairedDifference:
    """(mean, standard error) of a trial metric's difference trials[k] - others[k] over the trials paired by
    index (the same person seed) where both are finite, in the shown unit; (NaN, NaN) when none are."""
    values = [np.array([trial.metrics[key] for trial in group], dtype=float) for group in (trials, others)]
    difference = scale * (values[0] - values[1])
    difference = difference[np.isfinite(difference)]
    if not len(difference):
        return PairedDifference(float("nan"), float("nan"))
    return PairedDifference(float(np.mean(difference)),
                            float(np.std(difference, ddof=1) / np.sqrt(len(difference))) if len(difference) > 1 else 0.0)


def _pm(value: tuple[float, float] | None, signed: bool = False) -> str:
    if value is None or not np.isfinite(value[0]):
        return "–"
    return f"{'+' if signed and value[0] >= 0 else ''}{_fmt(value[0])} ± {_fmt(value[1])}"


def comparison_rows(results: dict[str, dict[str, list[SyncTrial]]], measures: dict = COMPARED) -> list[dict]:
    """One row per goal and policy: goal, policy, trials, and per measure its median, q25 and q75 in the
    shown unit (None where no trial has a finite value, e.g. the passive robot's goal error)."""
    rows = []
    for label, by_policy in results.items():
        for name, trials in by_policy.items():
            summary = summarise([trial.metrics for trial in trials])
            row = {"goal": label, "policy": name, "trials": len(trials)}
            for key, (_, scale) in measures.items():
                stats = summary.get(key, {})
                for stat in ("median", "q25", "q75"):
                    value = stats.get(stat)
                    row[f"{key}_{stat}"] = None if value is None else value * scale
            rows.append(row)
    return rows


def markdown_table(rows: list[dict], measures: dict = COMPARED) -> str:
    """The rows as a markdown table, each cell 'median [q25, q75]' in the heading's unit."""
    headings = ["goal", "policy"] + [heading for heading, _ in measures.values()]
    lines = ["| " + " | ".join(headings) + " |", "|" + "---|" * len(headings)]
    for row in rows:
        cells = [row["goal"], f"{row['policy']} (n={row['trials']})"]
        for key in measures:
            median, q25, q75 = (row[f"{key}_{s}"] for s in ("median", "q25", "q75"))
            cells.append("–" if median is None else f"{_fmt(median)} [{_fmt(q25)}, {_fmt(q75)}]")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def write_comparison(rows: list[dict], stem: Path, measures: dict = COMPARED) -> list[Path]:
    """Write ``stem.csv`` (one column per measure and statistic, in the shown units) and ``stem.md``."""
    stem = Path(stem)
    csv_path, md_path = stem.with_suffix(".csv"), stem.with_suffix(".md")
    with csv_path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    md_path.write_text(markdown_table(rows, measures))
    return [csv_path, md_path]


def _fmt(value: float) -> str:
    magnitude = abs(value)
    return f"{value:.3g}" if magnitude < 10 else f"{value:.0f}" if magnitude >= 100 else f"{value:.1f}"


__all__ = ["CANDIDATE", "COMPARED", "EFFORTS", "ERRORS", "GOAL_ERROR_BASELINE", "POLICIES", "compare_sync_policies", "compare_with_people",
           "comparison_rows", "markdown_table", "people_rows", "people_table", "write_comparison"]
