"""Print the robot-policy comparison block of docs/results/policy_comparison.md (sync scenario) from a fresh simulation
(``tools/regenerate_results.py policy-comparison`` puts it on its results page).

    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison [--trials 20] [--seed 0]

On a busy machine the goals can run in separate processes and be merged afterwards:

    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison --goals near,far --save /tmp/a.pkl
    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison --goals right,high --save /tmp/b.pkl
    PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison --load /tmp/a.pkl /tmp/b.pkl

(--policies re-runs some policies only; a later pickle's runs replace an earlier one's for the same goal and policy.)

Runs every robot policy (:data:`comanip.simulation.policies.POLICIES`) on the synchronisation scenario for
the near and far goals and two more (GOALS), ``--trials`` trials each with the same person seeds for every
policy, and writes studies/which_robot_policy_helps_the_person_in_sync/policy_comparison_sync.csv and .md (median [q25, q75] over the trials),
docs/figures/policy_comparison_sync.png, and prints the table with its verdicts (stdout; progress on stderr).
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np

from comanip.plots.policy_comparison_figure import plot_policy_comparison
from comanip.simulation import ScenarioSetup, SyncSettings
from comanip.simulation.policies import POLICIES
from comanip.simulation.policy_comparison import compare_sync_policies, comparison_rows, markdown_table, write_comparison
DOCS = Path(__file__).resolve().parent
#: label -> goal (m): the CLI's near and far goals, one to the robot's right and one higher and farther out.
GOALS = {"near": "near", "far": "far", "right": (0.35, -0.15, 0.20), "high": (0.60, 0.25, 0.30)}
#: The policy the verdicts are about, and the baselines it is compared with.
CANDIDATE = "continuous"


def verdicts(rows: list[dict]) -> list[str]:
    """One line per goal: does the candidate have a lower median goal error (mean over the reach and at the
    end) than every baseline, and a lower median RMS force change than prior-only and constant-velocity?"""
    lines = []
    for goal in dict.fromkeys(row["goal"] for row in rows):
        by_policy = {row["policy"]: row for row in rows if row["goal"] == goal}
        if CANDIDATE not in by_policy:
            lines.append(f"- {goal}: no `{CANDIDATE}` policy in this run")
            continue
        mine = by_policy[CANDIDATE]
        parts = []
        for key, what in (("goal_error_mean_m", "goal error over the reach"), ("goal_error_final_m", "goal error at the end")):
            others = {name: row[f"{key}_median"] for name, row in by_policy.items() if name != CANDIDATE and row[f"{key}_median"] is not None}
            worse = [f"{name} {value:.1f}" for name, value in others.items() if value <= mine[f"{key}_median"]]
            parts.append(f"{what} {mine[f'{key}_median']:.1f} mm: " +
                         ("lower than every baseline" if not worse else f"NOT lower than {', '.join(worse)} mm"))
        key = "rms_force_change_N"
        worse = [f"{name} {by_policy[name][f'{key}_median']:.2f}" for name in ("prior-only", "constant-velocity")
                 if name in by_policy and by_policy[name][f"{key}_median"] <= mine[f"{key}_median"]]
        parts.append(f"RMS force change {mine[f'{key}_median']:.2f} N: " +
                     ("lower than prior-only and constant-velocity" if not worse else f"NOT lower than {', '.join(worse)} N"))
        lines.append(f"- {goal}: " + "; ".join(parts))
    return lines


def add_run_arguments(parser: argparse.ArgumentParser, trials: int, per: str) -> None:
    """The options of the sync comparison scripts: --trials (default ``trials`` per ``per``), --seed, --goals,
    --save and --load."""
    parser.add_argument("--trials", type=int, default=trials, help=f"trials per {per} (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first trial's person (default: %(default)s)")
    parser.add_argument("--goals", default=",".join(GOALS), help="comma-separated labels of GOALS (default: all)")
    parser.add_argument("--save", type=Path, help="only simulate, and pickle the results here (for --load)")
    parser.add_argument("--load", type=Path, nargs="+", help="merge pickled results instead of simulating")


def load_runs(paths: list[Path]) -> tuple[list[dict], float, int, int]:
    """The pickled runs of --save, their summed wall time (s), and the first run's trials and seed."""
    runs = [pickle.loads(path.read_bytes()) for path in paths]
    return runs, sum(run["wall_s"] for run in runs), runs[0]["trials"], runs[0]["seed"]


def save_run(path: Path, results: dict, wall: float, trials: int, seed: int) -> None:
    """Pickle a run's results with its wall time (s), trials and seed, for --load."""
    path.write_bytes(pickle.dumps({"results": results, "wall_s": wall, "trials": trials, "seed": seed}))
    print(f"saved {path} ({wall / 60:.0f} min)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_run_arguments(parser, 20, "goal and policy")
    parser.add_argument("--policies", default=",".join(POLICIES), help="comma-separated policies (default: all)")
    args = parser.parse_args(argv)
    if args.load:
        runs, wall, trials, seed = load_runs(args.load)
        results = {}
        for run in runs:
            for label, by_policy in run["results"].items():
                results.setdefault(label, {}).update(by_policy)
        results = {label: {name: by_policy[name] for name in POLICIES if name in by_policy} for label, by_policy in results.items()}
        settings = {label: SyncSettings(goal=GOALS[label], trials=trials, seed=seed) for label in results}
    else:
        labels = [label for label in args.goals.split(",") if label]
        unknown = sorted(set(labels) - set(GOALS))
        if unknown:
            raise ValueError(f"--goals must name goals of {list(GOALS)}, got {unknown}")
        trials, seed = args.trials, args.seed
        settings = {label: SyncSettings(goal=GOALS[label], trials=trials, seed=seed) for label in labels}
        began = time.perf_counter()
        policies = [name for name in args.policies.split(",") if name]
        results = compare_sync_policies(settings, policies, ScenarioSetup(next(iter(settings.values()))), progress=True)
        wall = time.perf_counter() - began
        if args.save:
            save_run(args.save, results, wall, trials, seed)
            return 0
    rows = comparison_rows(results)
    files = write_comparison(rows, DOCS / "policy_comparison_sync")
    figure = plot_policy_comparison(results, DOCS.parents[1] / "docs" / "figures" / "policy_comparison_sync.png")
    goals = "; ".join(f"{label} {np.round(s.goal, 2).tolist()}" for label, s in settings.items())
    block = (f"Measured by `PYTHONPATH=src python -m studies.which_robot_policy_helps_the_person_in_sync.make_policy_comparison --trials {trials} --seed {seed}` "
             f"({trials} trials per goal and policy, person seeds {seed}–{seed + trials - 1} for every "
             f"policy; goals (m): {goals}; prior goal {list(next(iter(settings.values())).prior_goal)} m; "
             f"{wall / 60:.0f} min of simulation on the shared, loaded 2-core machine). Each cell: median [q25, q75] over "
             f"the trials; force and work from t_o = 0.2 s on.\n\n"
             f"{markdown_table(rows)}\n"
             f"Verdicts (does the continuous policy beat every baseline?):\n\n" + "\n".join(verdicts(rows)) + "\n\n"
             f"![policy comparison](../figures/{figure.name})")
    print(block)
    print("wrote", *[str(p) for p in files + [figure]], file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
