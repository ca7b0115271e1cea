"""Print the sync-task block of docs/results/policy_comparison.md: every robot policy on the paper's synchronisation
task (the person leads x–y, the robot the height) with the model's person at four paces and recorded arm reaches
(TAT-HUM's and each UE_ADL person's) at their speed and slower, each estimating robot carrying what it learned of
the person from trial to trial, and the task's targets (:mod:`comanip.simulation.sync_targets`), met or missed
(``tools/regenerate_results.py sync-task`` puts it on its page).

    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_sync_task_targets [--trials 10] [--seed 0] [--variant]

``--variant`` (with ``--load`` too): the person intends the height too (``SyncSettings.person_leads_height``). Needs the motion-capture arm reaches (a TAT-HUM data folder, ``--arm-reaches``, and UE_ADL's people, UE_ADL). As the people
comparison, people can run in separate processes (``--people``, ``--save``, ``--load``). Writes the targets' CSV
beside this script and the speed-profile figure (the model's person, every goal) to docs/figures/.
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402

from comanip.demo import GUIDING_FORCE_N  # noqa: E402
from comanip.plots.sync_speed_profiles import plot_speed_profiles  # noqa: E402
from comanip.simulation import PersonParameters, SyncSettings  # noqa: E402
from comanip.simulation.policy_comparison import CANDIDATE, people_rows, people_table  # noqa: E402
from comanip.simulation.sync_targets import (REQUIRED, pairs_table, robots_table, target_rows, target_summary,  # noqa: E402
                                             targets_table)
from studies.which_robot_policy_helps_the_person_in_sync.make_people_comparison import ARM_REACHES, run_or_load  # noqa: E402
from studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison import (  # noqa: E402
    GOALS, add_run_arguments)

HERE = Path(__file__).resolve().parent

#: The UE_ADL people's Vicon Nexus exports, one folder per person (../shared/data/arm_reaches/README.md); only the
#: development split's people are read, each from their own folder.
UE_ADL = HERE.parents[2] / "shared" / "data" / "arm_reaches" / "ue_adl"
#: The UE_ADL people the run meets.
UE_ADL_PEOPLE = tuple(f"ADL{k:03d}" for k in range(1, 11))
#: The slow-down every recorded person gets on the results page (their reaches then take about the model person's
#: time with the handle).
SLOWED = 2.5

#: label -> the simulated person: the model's person at ×0.7–×1.6 of its pace, TAT-HUM's recorded arm reaches
#: (``--arm-reaches``) and each UE_ADL person's at their recorded speed and SLOWED times slower.
PEOPLE = {
    "model-x0.7": PersonParameters(pace=0.7),
    "model": PersonParameters(),
    "model-x1.3": PersonParameters(pace=1.3),
    "model-x1.6": PersonParameters(pace=1.6),
    **{f"{name}{suffix}": PersonParameters(hand_path="recorded-arm", pace=pace)
       for name in ("arm", *UE_ADL_PEOPLE) for suffix, pace in (("", 1.0), (f"-x{SLOWED:g}", SLOWED))},
}
#: label -> the folder of a UE_ADL person's reaches (the other arm people's: ``--arm-reaches``).
ARM_FOLDERS = {label: UE_ADL / label.split("-")[0] for label in PEOPLE if label.startswith("ADL")}
#: The people whose peak force the guiding-force target asks about: the model's people and the slowed arms.
GUIDING_PEOPLE = tuple(label for label, person in PEOPLE.items() if person.hand_path == "model" or person.pace == SLOWED)
#: people group -> whether a label of PEOPLE belongs to it (the block's table by group).
GROUPS = {
    "the model's person": lambda label: label.startswith("model"),
    "TAT-HUM's arm": lambda label: label == "arm",
    f"TAT-HUM's arm ×{SLOWED:g}": lambda label: label == f"arm-x{SLOWED:g}",
    "UE_ADL at their speed": lambda label: label.startswith("ADL") and "-x" not in label,
    f"UE_ADL ×{SLOWED:g}": lambda label: label.startswith("ADL") and label.endswith(f"-x{SLOWED:g}"),
}
#: The robots the figure shows.
FIGURE_POLICIES = ("passive", "admittance", "onset-minimum-jerk", "forecast")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_run_arguments(parser, 10, "person, goal and policy")
    parser.add_argument("--people", default=",".join(PEOPLE), help="comma-separated labels of PEOPLE (default: all)")
    parser.add_argument("--variant", action="store_true", help="the person intends the height too")
    parser.add_argument("--arm-reaches", type=Path, default=ARM_REACHES,
                        help="TAT-HUM data folder of the arm and arm-x2.5 people's reaches (default: %(default)s; the "
                             "ADLnnn people's are in UE_ADL)")
    args = parser.parse_args(argv)
    run = run_or_load(args, PEOPLE, person_leads_height=args.variant, arm_folders=ARM_FOLDERS, carry_calibration=True)
    if run is None:
        return 0
    results, wall, trials, seed = run
    print(block(results, trials, seed, wall, args.variant))
    return 0


def block(results: dict, trials: int, seed: int, wall: float, variant: bool) -> str:
    """The results page's block for results {person: {goal: {policy: trials}}}."""
    goals = list(next(iter(results.values())))
    policies = list(next(iter(next(iter(results.values())).values())))
    rows = target_rows(results, GUIDING_FORCE_N, guiding_people=GUIDING_PEOPLE)
    suffix = "_variant" if variant else ""
    _write_csv(rows, HERE / f"sync_task_targets{suffix}.csv")
    figure_person = "model" if "model" in results else next(iter(results))
    figure = plot_speed_profiles(results[figure_person], HERE.parents[1] / "docs" / "figures" / f"sync_task_speeds{suffix}.png",
                                 [name for name in FIGURE_POLICIES if name in policies],
                                 f"{figure_person}: the person's x–y and the robot's z speed over t / MT (mean ± std)")
    people_option = "" if list(results) == list(PEOPLE) else f" --people {','.join(results)}"
    goal_text = "; ".join(f"{label} {np.round(SyncSettings(goal=GOALS[label]).goal, 2).tolist()}" for label in goals)
    task = ("the variant: the person intends the height too" if variant else
            "the paper's task: the person leads x–y, their arm follows the height the robot leads")
    low, high = GUIDING_FORCE_N
    return (f"Measured by `PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_sync_task_targets "
            f"--trials {trials} --seed {seed}{people_option}{' --variant' if variant else ''}` ({task}; {trials} trials per "
            f"person, goal and policy, person seeds {seed}–{seed + trials - 1} for every policy; goals (m): {goal_text}; "
            f"people: {', '.join(results)}; {wall / 60:.0f} min of simulation, summed over processes, on the shared 2-core "
            f"machine). The candidate is `forecast`; force change and work from t_o = 0.2 s on; a group's arrival when "
            f"its speed (x–y: the person's, z: the robot's) first falls below 5 % of its peak after it; lags and the "
            f"height error as medians over the trials.\n\n"
            f"{targets_table(rows)}\n"
            f"By people group (pairs meeting each target of those it is asked of):\n\n"
            f"{_groups_table(rows)}\n"
            f"Per person and goal (bold: the target missed; the guiding force, {low:.0f}–{high:.0f} N, is asked of "
            f"{', '.join(p for p in GUIDING_PEOPLE if p in results)}):\n\n"
            f"{pairs_table(rows)}\n"
            f"{_calibration_text(results)}\n\n"
            f"Every robot held to the same targets (pairs meeting each; \"below every other robot's\" against all the "
            f"others):\n\n"
            f"{robots_table(results, GUIDING_FORCE_N, GUIDING_PEOPLE)}\n"
            f"Every robot's RMS force change (mean ± std over the trials; paired differences `forecast` minus the other "
            f"robot, mean ± standard error):\n\n"
            f"{people_table(people_rows(results), policies, goal_error=False)}\n"
            f"![speed profiles](../figures/{figure.name})")


def _groups_table(rows: list[dict]) -> str:
    """Per people group of GROUPS with rows: the pairs meeting each target, as a markdown table."""
    lines = ["| people | " + " | ".join(what for what, _ in REQUIRED.values()) + " |", "|" + "---|" * (len(REQUIRED) + 1)]
    for group, member in GROUPS.items():
        mine = [row for row in rows if member(row["person"])]
        if mine:
            cells = ["–" if asked == 0 else f"{met} of {asked}" for met, asked, _ in target_summary(mine).values()]
            lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _calibration_text(results: dict) -> str:
    """What the candidate robot had learned of each person when its last trial at each goal began (carried
    calibration: it learns from a trial whose handle came to rest within it): the reaches learned from, per goal,
    and the range over the goals of its amplitude and spread factors."""
    parts = []
    for person, by_goal in results.items():
        last = [by_policy[CANDIDATE][-1].metrics for by_policy in by_goal.values()]
        text = f"{person} {', '.join(str(metrics.get('calibration_reaches', 0)) for metrics in last)}"
        if any(metrics.get("calibration_reaches", 0) for metrics in last):
            text += " (" + ", ".join(f"{factor} {_range([metrics[f'calibration_{factor}'] for metrics in last])}"
                                     for factor in ("amplitude", "spread")) + ")"
        parts.append(text)
    trials = len(next(iter(next(iter(results.values())).values()))[CANDIDATE])
    return (f"Each estimating robot carries what it learned of the person from trial to trial of a goal, in seed order "
            f"(`SyncSettings.carry_calibration`); it learns from a trial whose handle came to rest within it. What "
            f"`{CANDIDATE}` had learned when its last trial began: the reaches learned from (of {trials - 1}) at each goal "
            f"and, where any, the range of its amplitude and spread factors over the goals (1: a person not seen yet): "
            f"{'; '.join(parts)}. Its trials that began knowing nothing of the person against those that began with a "
            f"learned calibration, by people group (median height error at the person's arrival; mean RMS force "
            f"beyond holding): {_calibrated_against_not(results)}.")


def _calibrated_against_not(results: dict) -> str:
    """Per people group, the candidate's trials that began with no reach learned against those that began with one or
    more: their number, median height error at arrival (mm) and mean RMS force change (N)."""
    parts = []
    for group, member in GROUPS.items():
        trials = [trial.metrics for person, by_goal in results.items() if member(person)
                  for by_policy in by_goal.values() for trial in by_policy[CANDIDATE]]
        if not trials:
            continue
        texts = []
        for learned in (False, True):
            mine = [metrics for metrics in trials if bool(metrics.get("calibration_reaches", 0)) == learned]
            height = np.nanmedian([metrics["height_error_at_arrival_m"] for metrics in mine]) if mine else np.nan
            force = np.nanmean([metrics["rms_force_change_N"] for metrics in mine]) if mine else np.nan
            texts.append(f"{len(mine)} trials, {1e3 * height:.0f} mm, {force:.1f} N" if mine else "no trials")
        parts.append(f"{group}: {texts[0]} against {texts[1]}")
    return "; ".join(parts)


def _range(values: list[float]) -> str:
    low, high = min(values), max(values)
    return f"{low:.2g}" if f"{low:.2g}" == f"{high:.2g}" else f"{low:.2g}–{high:.2g}"


def _write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print("wrote", path, file=sys.stderr)


if __name__ == "__main__":
    raise SystemExit(main())
