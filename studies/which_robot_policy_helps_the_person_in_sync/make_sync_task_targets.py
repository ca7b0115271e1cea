"""Print the sync-task block of docs/results/policy_comparison.md: every robot policy on the paper's synchronisation
task (the person leads x–y, the robot the height) with the model's person at four paces and recorded arm reaches at
their speed and slower, and the task's targets (:mod:`comanip.simulation.sync_targets`), met or missed
(``tools/regenerate_results.py sync-task`` puts it on its page).

    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_sync_task_targets [--trials 10] [--seed 0] [--variant]

``--variant`` (with ``--load`` too): the person intends the height too (``SyncSettings.person_leads_height``). Needs the motion-capture arm reaches (a TAT-HUM data folder, ``--arm-reaches``). As the people
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
from comanip.simulation.policy_comparison import people_rows, people_table  # noqa: E402
from comanip.simulation.sync_targets import pairs_table, robots_table, target_rows, targets_table  # noqa: E402
from studies.which_robot_policy_helps_the_person_in_sync.make_people_comparison import ARM_REACHES, run_or_load  # noqa: E402
from studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison import (  # noqa: E402
    GOALS, add_run_arguments)

HERE = Path(__file__).resolve().parent

#: label -> the simulated person: the model's person at ×0.7–×1.6 of its pace, and recorded arm reaches at their
#: recorded speed and 2.5 times slower (the slow-down every recorded person gets on the results page).
PEOPLE = {
    "model-x0.7": PersonParameters(pace=0.7),
    "model": PersonParameters(),
    "model-x1.3": PersonParameters(pace=1.3),
    "model-x1.6": PersonParameters(pace=1.6),
    "arm": PersonParameters(hand_path="recorded-arm"),
    "arm-x2.5": PersonParameters(hand_path="recorded-arm", pace=2.5),
}
#: The people whose peak force the guiding-force target asks about: the model's people and the slowed arms.
GUIDING_PEOPLE = ("model-x0.7", "model", "model-x1.3", "model-x1.6", "arm-x2.5")
#: The robots the figure shows.
FIGURE_POLICIES = ("passive", "admittance", "onset-minimum-jerk", "forecast")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_run_arguments(parser, 10, "person, goal and policy")
    parser.add_argument("--people", default=",".join(PEOPLE), help="comma-separated labels of PEOPLE (default: all)")
    parser.add_argument("--variant", action="store_true", help="the person intends the height too")
    parser.add_argument("--arm-reaches", type=Path, default=ARM_REACHES,
                        help="TAT-HUM data folder of the arm people's reaches (default: %(default)s)")
    args = parser.parse_args(argv)
    run = run_or_load(args, PEOPLE, person_leads_height=args.variant)
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
            f"Per person and goal (bold: the target missed; the guiding force, {low:.0f}–{high:.0f} N, is asked of "
            f"{', '.join(p for p in GUIDING_PEOPLE if p in results)}):\n\n"
            f"{pairs_table(rows)}\n"
            f"Every robot held to the same targets (pairs meeting each; \"below every other robot's\" against all the "
            f"others):\n\n"
            f"{robots_table(results, GUIDING_FORCE_N, GUIDING_PEOPLE)}\n"
            f"Every robot's RMS force change (mean ± std over the trials; paired differences `forecast` minus the other "
            f"robot, mean ± standard error):\n\n"
            f"{people_table(people_rows(results), policies, goal_error=False)}\n"
            f"![speed profiles](../figures/{figure.name})")


def _write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print("wrote", path, file=sys.stderr)


if __name__ == "__main__":
    raise SystemExit(main())
