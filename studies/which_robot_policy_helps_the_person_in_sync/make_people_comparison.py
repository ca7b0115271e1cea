"""Print the people-comparison block of docs/results/policy_comparison.md: the robot policies on the sync scenario
with simulated people who are not the model (``tools/regenerate_results.py policy-people`` puts it on its page).

    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_people_comparison [--trials 10] [--seed 0]

Needs the mouse recordings (``pip install -e ".[data]"``) and the motion-capture arm reaches (a TAT-HUM data
folder, ``--arm-reaches``; default ``../shared/data/arm_reaches/tathum/data_3d`` beside the clone). On a busy machine the people can run in separate processes
and be merged afterwards:

    ... make_people_comparison.py --people model,x0.7,x1.3 --save /tmp/a.pkl
    ... make_people_comparison.py --people recorded,recorded-x2.5,arm,arm-x2.5 --save /tmp/b.pkl
    ... make_people_comparison.py --load /tmp/a.pkl /tmp/b.pkl

Every policy of :data:`comanip.simulation.policies.POLICIES` meets every person of PEOPLE at every goal of GOALS,
``--trials`` trials each (trial k: person seed + k for every policy; a recorded person's seed picks its
recording of the development split; the continuous and forecast policies' goal estimator uses the person's
:func:`online_preset`). Prints, per person and goal, the forecast policy's (CANDIDATE's) mean goal and forecast errors from t_o to MT against constant
velocity's and every policy's RMS force change and the person's work beyond holding (mean ± std over the
trials), with the verdicts; writes the table's CSV beside this script and docs/figures/policy_comparison_people.png (progress on
stderr).
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from collections import Counter
from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from comanip.plots.figure_file import save_figure  # noqa: E402
from comanip.simulation import PersonParameters, ScenarioSetup, SyncSettings  # noqa: E402
from comanip.simulation.policies import POLICIES  # noqa: E402
from comanip.simulation.policy_comparison import CANDIDATE, GOAL_ERROR_BASELINE, compare_with_people, people_rows, people_table  # noqa: E402

HERE = Path(__file__).resolve().parent
from comanip.demo import GUIDING_FORCE_N  # noqa: E402
from studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison import (  # noqa: E402
    GOALS, add_run_arguments, load_runs, save_run)

ARM_REACHES = HERE.parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"

#: label -> the simulated person: the model's own, the model 30 % faster and slower, a recorded person (mouse
#: movement) at the recording's timing, and the same recordings played 2.5 times slower (their median movement,
#: 0.56 s, then takes about the model person's time with the handle); and the same two with motion-capture arm
#: reaches in 3-D (slowed by the same factor as the mouse movements: one rule for every recorded person).
PEOPLE = {
    "model": PersonParameters(),
    "x0.7": PersonParameters(pace=0.7),
    "x1.3": PersonParameters(pace=1.3),
    "recorded": PersonParameters(hand_path="recorded"),
    "recorded-x2.5": PersonParameters(hand_path="recorded", pace=2.5),
    "arm": PersonParameters(hand_path="recorded-arm"),
    "arm-x2.5": PersonParameters(hand_path="recorded-arm", pace=2.5),
}



def online_preset(person: PersonParameters) -> str | None:
    """The preset of the continuous and forecast policies' online goal estimator with that person
    (SyncSettings.online_preset; None: the scenario's Cartesian preset): the arm preset, made for a person's hand in
    3-D, with the arm people (``hand_path="recorded-arm"``)."""
    return "arm" if person.hand_path == "recorded-arm" else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_run_arguments(parser, 10, "person, goal and policy")
    parser.add_argument("--people", default=",".join(PEOPLE), help="comma-separated labels of PEOPLE (default: all)")
    parser.add_argument("--arm-reaches", type=Path, default=ARM_REACHES,
                        help="TAT-HUM data folder of the arm people's reaches (default: %(default)s)")
    args = parser.parse_args(argv)
    run = run_or_load(args, PEOPLE)
    if run is None:
        return 0
    results, wall, trials, seed = run
    goals = list(next(iter(results.values())))
    policies = list(next(iter(next(iter(results.values())).values())))
    rows = people_rows(results)
    _write_csv(rows, HERE / "people_comparison_sync.csv")
    figure = _figure(rows, policies, HERE.parents[1] / "docs" / "figures" / "policy_comparison_people.png")
    goal_text = "; ".join(f"{label} {np.round(SyncSettings(goal=GOALS[label]).goal, 2).tolist()}" for label in goals)
    misses = [row for row in rows if not row.get("goal_error_below", True)]
    forecast_misses = [row for row in rows if not row.get("forecast_error_below", True)]
    low, high = GUIDING_FORCE_N
    peaks = [row[f"peak_force_{CANDIDATE}_N"][0] for row in rows if f"peak_force_{CANDIDATE}_N" in row]
    within = [peak for peak in peaks if low <= peak <= high]
    people_option = "" if list(results) == list(PEOPLE) else f" --people {','.join(results)}"
    heavier = [row for row in rows if row.get("force_change_above")]
    more_work = [row for row in rows if row.get("work_above")]
    above_passive = [row for row in rows if "passive" in row.get("work_above", [])]
    presets_text = "; ".join(f"{label}: `{online_preset(PEOPLE[label])}`" for label in results if online_preset(PEOPLE[label]))
    block = (f"Measured by `PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_people_comparison "
             f"--trials {trials} --seed {seed}{people_option}` ({trials} trials per person, goal and policy, person seeds {seed}–{seed + trials - 1} "
             f"for every policy; goals (m): {goal_text}; people: {', '.join(results)}; the continuous and forecast policies' estimator "
             f"preset: `cartesian`{'; ' + presets_text if presets_text else ''}; {wall / 60:.0f} min of simulation, "
             f"summed over processes, on the shared 2-core machine). Each cell: mean ± standard deviation over the "
             f"trials; goal error averaged from t_o = 0.2 s to the movement time MT, forecast error the RMS distance of each "
             f"prediction's rest motion from the handle until MT averaged over the predictions from t_o to MT, force "
             f"change from t_o on. Paired "
             f"differences (`{CANDIDATE}` minus the other policy, trial by trial: the same person meets every policy): "
             f"mean ± standard error.\n\n"
             f"{people_table(rows, policies)}\n"
             f"The person's work beyond holding the object, from t_o on (J; the same trials):\n\n"
             f"{people_table(rows, policies, 'work', goal_error=False)}\n"
             f"The person's peak force change, from t_o on (N; the same trials), against the {low:.0f}–{high:.0f} N "
             f"partners exchange when one guides the other through a held contact (Sawers et al. 2017):\n\n"
             f"{people_table(rows, policies, 'peak_force', goal_error=False)}\n"
             f"`{CANDIDATE}` below `{GOAL_ERROR_BASELINE}` in mean goal error: {len(rows) - len(misses)} of {len(rows)} "
             f"person–goal pairs, in mean forecast error: {len(rows) - len(forecast_misses)} of {len(rows)}; its mean peak "
             f"force change within {low:.0f}–{high:.0f} N: {len(within)} of {len(peaks)}; RMS force change not above any baseline's: {len(rows) - len(heavier)} of {len(rows)}; "
             f"person's work below the passive robot's: {len(rows) - len(above_passive)} of {len(rows)}, not above any "
             f"baseline's: {len(rows) - len(more_work)} of {len(rows)}.\n\n"
             f"{_verdicts_by_person(rows, results)}\n"
             f"![policies with people who are not the model](../figures/{figure.name})")
    print(block)
    print("wrote", HERE / "people_comparison_sync.csv", file=sys.stderr)
    return 0


def _verdicts_by_person(rows: list[dict], results: dict) -> str:
    """One line per person: the goals where the candidate's mean goal error is below the baseline's, those
    where the person's mean work beyond holding is below the passive robot's, and the statuses of the
    candidate's last estimates over the person's trials."""
    lines = []
    for person in dict.fromkeys(row["person"] for row in rows):
        mine = [row for row in rows if row["person"] == person]
        below = [row["goal"] for row in mine if row.get("goal_error_below")]
        lighter = [row["goal"] for row in mine if "passive" not in row.get("work_above", ["passive"])]
        statuses = Counter(str(trial.estimate.status) for by_policy in results[person].values()
                           for trial in by_policy.get(CANDIDATE, []) if trial.estimate is not None)
        lines.append(f"- {person}: `{CANDIDATE}` below `{GOAL_ERROR_BASELINE}` in goal error at "
                     f"{', '.join(below) or 'no goal'} ({len(below)} of {len(mine)}); person's work below the passive "
                     f"robot's at {', '.join(lighter) or 'no goal'} ({len(lighter)} of {len(mine)}); status of "
                     f"`{CANDIDATE}`'s last estimate: {', '.join(f'{name} {count}' for name, count in statuses.most_common())}")
    return "\n".join(lines) + "\n"


def _figure(rows: list[dict], policies: list[str], path: Path) -> Path:
    """Per person (columns): the candidate policy's and constant velocity's mean goal error per goal (top),
    every policy's RMS force change (middle) and the person's work beyond holding (bottom) per goal, bars at the
    mean, error bars one standard deviation."""
    people = list(dict.fromkeys(row["person"] for row in rows))
    colors = dict(zip(policies, plt.cm.tab10(np.arange(len(policies)))))
    fig, axes = plt.subplots(3, len(people), figsize=(3.6 * len(people), 9.4), squeeze=False)
    for column, person in enumerate(people):
        mine = [row for row in rows if row["person"] == person]
        goals = np.arange(len(mine))
        for ax, names, key, width in ((axes[0, column], (CANDIDATE, GOAL_ERROR_BASELINE), "goal_error_{}_mm", 0.38),
                                      (axes[1, column], policies, "force_change_{}_N", 0.8 / len(policies)),
                                      (axes[2, column], policies, "work_{}_J", 0.8 / len(policies))):
            for k, name in enumerate(names):
                mean, std = np.array([row.get(key.format(name), (np.nan, np.nan)) for row in mine]).T
                ax.bar(goals + (k - (len(names) - 1) / 2) * width, mean, width, yerr=std, color=colors[name], label=name,
                       error_kw={"lw": 0.8})
            ax.set_xticks(goals, [row["goal"] for row in mine])
        axes[0, column].set_title(person)
    axes[0, 0].set_ylabel("goal error, mean t_o–MT (mm)")
    axes[1, 0].set_ylabel("RMS force change (N)")
    axes[2, 0].set_ylabel("work beyond holding (J)")
    axes[0, 0].legend(fontsize=8)
    axes[1, 0].legend(fontsize=7)
    fig.tight_layout()
    return save_figure(fig, path)


def run_or_load(args, people: dict, person_leads_height: bool = False, arm_folders: dict | None = None,
                carry_calibration: bool = False):
    """The comparison's results {person: {goal: {policy: trials}}}, its wall time (s), trials and seed, for the
    ``people`` {label: PersonParameters} named by ``args.people`` and the goals of ``args.goals``: loaded from the
    runs of ``args.load``, or simulated (``person_leads_height``: the variant of the task; ``carry_calibration``:
    each estimating robot keeps what it learned of the person from trial to trial, SyncSettings.carry_calibration)
    and, with ``args.save``, saved there instead (then None). An arm person's reaches come from their
    ``arm_folders`` entry (label -> folder), else from ``args.arm_reaches``."""
    if args.load:
        runs, wall, trials, seed = load_runs(args.load)
        results = {}
        for run in runs:
            results.update(run["results"])
        return {label: results[label] for label in people if label in results}, wall, trials, seed
    goals = [label for label in args.goals.split(",") if label]
    chosen = [label for label in args.people.split(",") if label]
    unknown = sorted(set(goals) - set(GOALS)) + sorted(set(chosen) - set(people))
    if unknown:
        raise ValueError(f"--goals must name goals of {list(GOALS)} and --people people of {list(people)}, got {unknown}")
    settings = {label: SyncSettings(goal=GOALS[label], trials=args.trials, seed=args.seed, carry_calibration=carry_calibration,
                                    person_leads_height=person_leads_height) for label in goals}
    setups: dict[Path, ScenarioSetup] = {}
    began = time.perf_counter()
    results = {}
    for label in chosen:
        folder = Path((arm_folders or {}).get(label, args.arm_reaches))
        setup = setups.setdefault(folder, ScenarioSetup(next(iter(settings.values())), arm_reaches=folder))
        mine = {goal: replace(goal_settings, online_preset=online_preset(people[label])) for goal, goal_settings in settings.items()}
        results.update(compare_with_people(mine, {label: people[label]}, list(POLICIES), setup, progress=True))
    wall = time.perf_counter() - began
    if args.save:
        save_run(args.save, results, wall, args.trials, args.seed)
        return None
    return results, wall, args.trials, args.seed


def _write_csv(rows: list[dict], path: Path) -> None:
    """One line per person and goal; (mean, std) pairs split into two columns, lists joined by spaces."""
    flat = []
    for row in rows:
        out = {}
        for key, value in row.items():
            if isinstance(value, tuple):
                out[f"{key}_mean"], out[f"{key}_std"] = value
            elif isinstance(value, list):
                out[key] = " ".join(value)
            else:
                out[key] = value
        flat.append(out)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(dict.fromkeys(key for row in flat for key in row)))
        writer.writeheader()
        writer.writerows(flat)


if __name__ == "__main__":
    raise SystemExit(main())
