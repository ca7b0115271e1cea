"""The continuous policy's goal error in the sync scenario for several beliefs of the online estimator: the
open-loop one (a deviation from the plan persists) and a person who corrects (comanip.estimation.
corrected_deviation: correction time tau, speed-scaled deviations sigma_t). Writes studies/does_a_correcting_person_belief_stop_the_drift/online_drift.md.

    PYTHONPATH=src python -m studies.does_a_correcting_person_belief_stop_the_drift.measure_online_drift [--trials 3]

Prints, per (tau, sigma_t) and goal, the median over the trials of the goal error at t_o, its mean from t_o to
MT and at the end (mm), and the goal error over time of one trial (far goal, person seed 0).
"""

from __future__ import annotations

import argparse
import time
from functools import partial
from pathlib import Path

import numpy as np

from comanip.estimation import OnlineOptions
from comanip.simulation import ScenarioSetup, SyncSettings
from comanip.simulation.policies import POLICIES
from comanip.simulation.policy_comparison import compare_sync_policies, comparison_rows
from comanip.simulation.sync_scenario import run_sync
from make_policy_comparison import GOALS

DOCS = Path(__file__).resolve().parent
#: (tau s or None, sigma_t s): the open-loop belief, corrections alone, and the chosen default with neighbours.
BELIEFS = [(None, 0.0), (0.3, 0.0), (0.11, 0.15), (0.22, 0.1), (0.3, 0.15), (0.5, 0.1)]
TRACE_TIMES = (0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.5, 2.0, 2.5)


def with_belief(tau, sigma):
    """The continuous policy class bound to the estimator options of one belief."""
    return partial(POLICIES["continuous"], options=OnlineOptions(correction_time=tau, deviation_time=sigma))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--trials", type=int, default=3, help="trials per goal and belief (default: %(default)s)")
    args = parser.parse_args()
    original = POLICIES["continuous"]
    lines = ["| tau (s) | sigma_t (s) | goal | error at t_o (mm) | mean t_o–MT (mm) | at the end (mm) |", "|---|---|---|---|---|---|"]
    trace = ["| tau (s) | sigma_t (s) | " + " | ".join(f"{t:g} s" for t in TRACE_TIMES) + " | end |",
             "|---|---|" + "---|" * (len(TRACE_TIMES) + 1)]
    t_begin = time.time()
    settings = {label: SyncSettings(goal=GOALS[label], trials=args.trials, seed=0) for label in GOALS}
    setup = ScenarioSetup(next(iter(settings.values())))
    try:
        for tau, sigma in BELIEFS:
            POLICIES["continuous"] = with_belief(tau, sigma)
            rows = comparison_rows(compare_sync_policies(settings, ["continuous"], setup))
            for row in rows:
                lines.append(f"| {tau or 'open loop'} | {sigma:g} | {row['goal']} | {row['goal_error_first_m_median']:.0f} | "
                             f"{row['goal_error_mean_m_median']:.1f} | {row['goal_error_final_m_median']:.1f} |")
                print(lines[-1], flush=True)
            record = run_sync(SyncSettings(goal=GOALS["far"], trials=1, seed=0, policy="continuous"), setup, progress=False)[0].record
            error = 1e3 * np.linalg.norm(record.goal_estimate - record.goal, axis=1)
            at = [error[min(int(np.searchsorted(record.t, t)), len(error) - 1)] for t in TRACE_TIMES]
            trace.append(f"| {tau or 'open loop'} | {sigma:g} | " + " | ".join(f"{e:.0f}" for e in at) + f" | {error[-1]:.1f} |")
            print(trace[-1], flush=True)
    finally:
        POLICIES["continuous"] = original
    text = (f"# The continuous goal estimate against a person who corrects\n\n"
            f"Measured by `PYTHONPATH=src python -m studies.does_a_correcting_person_belief_stop_the_drift.measure_online_drift --trials {args.trials}` "
            f"({time.time() - t_begin:.0f} s; sync scenario, person seeds 0–{args.trials - 1}, the continuous policy "
            "with the online estimator's belief set as in the first two columns; "
            "`comanip.estimation.online.corrected_deviation`). Medians over the trials:\n\n" + "\n".join(lines) +
            "\n\nGoal error (mm) over time of one trial (far goal, seed 0):\n\n" + "\n".join(trace) + "\n")
    (DOCS / "online_drift.md").write_text(text)
    print(f"wrote {DOCS / 'online_drift.md'}")


if __name__ == "__main__":
    main()
