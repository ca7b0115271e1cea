"""Rewrite the robot-policy comparison in README.md (sync scenario, issue 12) from a fresh simulation, so that
no number in it is typed by hand.

    PYTHONPATH=src python docs/make_policy_comparison.py [--trials 20] [--seed 0] [--readme README.md]

Runs every robot policy (:data:`comanip.simulation.policies.POLICIES`) on the synchronisation scenario for
the near and far goals and two more (GOALS), ``--trials`` trials each with the same person seeds for every
policy, and writes docs/policy_comparison_sync.csv and .md (median [q25, q75] over the trials),
docs/figures/policy_comparison_sync.png, and the table with its verdicts between the markers
``<!-- policy-comparison:begin -->`` and ``<!-- policy-comparison:end -->`` in the README.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from comanip.plots.policy_comparison import plot_policy_comparison
from comanip.simulation import ScenarioSetup, SyncSettings
from comanip.simulation.policies import POLICIES
from comanip.simulation.policy_comparison import compare_sync_policies, comparison_rows, markdown_table, write_comparison
from make_calibration_table import replace_block

BEGIN = "<!-- policy-comparison:begin -->"
END = "<!-- policy-comparison:end -->"
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=20, help="trials per goal and policy (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first trial's person (default: %(default)s)")
    parser.add_argument("--readme", type=Path, default=DOCS.parent / "README.md")
    args = parser.parse_args(argv)
    settings = {label: SyncSettings(goal=goal, trials=args.trials, seed=args.seed) for label, goal in GOALS.items()}
    began = time.perf_counter()
    results = compare_sync_policies(settings, list(POLICIES), ScenarioSetup(next(iter(settings.values()))), progress=True)
    wall = time.perf_counter() - began
    rows = comparison_rows(results)
    files = write_comparison(rows, DOCS / "policy_comparison_sync")
    figure = plot_policy_comparison(results, DOCS / "figures" / "policy_comparison_sync.png")
    goals = "; ".join(f"{label} {np.round(s.goal, 2).tolist()}" for label, s in settings.items())
    block = (f"Measured by `PYTHONPATH=src python docs/make_policy_comparison.py --trials {args.trials} --seed {args.seed}` "
             f"({args.trials} trials per goal and policy, person seeds {args.seed}–{args.seed + args.trials - 1} for every "
             f"policy; goals (m): {goals}; prior goal {list(next(iter(settings.values())).prior_goal)} m; "
             f"{wall / 60:.0f} min on the shared 2-core machine). Each cell: median [q25, q75] over the trials; force "
             f"and work from t_o = 0.2 s on.\n\n"
             f"{markdown_table(rows)}\n"
             f"Verdicts (issue 12's \"done when\"):\n\n" + "\n".join(verdicts(rows)) + "\n\n"
             f"![policy comparison]({figure.relative_to(DOCS.parent)})")
    args.readme.write_text(replace_block(args.readme.read_text(), block, BEGIN, END))
    print(block)
    print("wrote", *[str(p) for p in files + [figure, args.readme]])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
