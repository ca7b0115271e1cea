"""Robot policies compared on the synchronisation scenario over the same trials and person seeds.

Every policy meets the same people: trial k of a goal uses seed + k whatever the robot does, so the
differences between policies are the robot's. Each measure (:mod:`comanip.simulation.measures`) is
summarised per goal and policy by its median and interquartile range over the trials.

>>> results = compare_sync_policies({"near": SyncSettings(goal="near", trials=20)}, list(POLICIES))
>>> rows = comparison_rows(results)
>>> write_comparison(rows, Path("out/sync_policies"))      # .csv and .md
"""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

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


__all__ = ["COMPARED", "POLICIES", "compare_sync_policies", "comparison_rows", "markdown_table", "write_comparison"]
