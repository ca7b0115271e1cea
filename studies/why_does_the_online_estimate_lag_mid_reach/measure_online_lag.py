"""Why the continuous goal estimate lags in the middle of a sync reach: writes studies/why_does_the_online_estimate_lag_mid_reach/online_lag.md.

    PYTHONPATH=src python -m studies.why_does_the_online_estimate_lag_mid_reach.measure_online_lag [--trials 5] [--seed 20]

Runs the constant-velocity and continuous robots on the sync scenario's four goals (``--trials`` person seeds
from ``--seed``; by default seeds the README's table does not use), then prints, as medians over the trials:

1. the goal error (mm) over time of both robots;
2. how far along the reach the hand is (projection of hand minus start on the goal's direction, over the
   distance), per axis group: the person-led x-y and the robot-led z, beside the model's plan to the true
   goal (the open-loop mean the estimator matches);
3. the continuous robot's recorded handle observations replayed into the online estimator with other
   settings (the prior, the belief, the robot-led z axis; :class:`comanip.estimation.OnlineOptions`): the goal
   error over time each would have given on the same observations (open loop: the robot's motion would
   itself change with the estimate).
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from comanip.estimation import OnlineGoalEstimator, OnlineOptions
from comanip.estimation.streaming import online_settings
from comanip.simulation import ScenarioSetup, SyncSettings
from comanip.simulation.policy_comparison import compare_sync_policies
from make_policy_comparison import GOALS

DOCS = Path(__file__).resolve().parent
TIMES = (0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0, 1.2, 1.5, 2.0)
ROBOT = online_settings.load("sync_robot")
PRIOR_STD, ROBOT_BELIEF, CORRECTING_PERSON = ROBOT.prior_std, ROBOT.options, online_settings.load("correcting").options
"""The sync robot's prior std and belief, and a person who corrects (the shipped descriptions)."""
#: label -> (prior std m, options) of the replayed estimator.
REPLAYS = {
    "the policy's (ROBOT_BELIEF: prior 0.25 m, a person who corrects, robot-led z)": (PRIOR_STD, ROBOT_BELIEF),
    "z read as the person's (CORRECTING_PERSON, the policy before)": (PRIOR_STD, CORRECTING_PERSON),
    "weak prior (10 m)": (None, ROBOT_BELIEF),
    "no straying on x-y (sigma_t = 0)": (PRIOR_STD, dataclasses.replace(ROBOT_BELIEF, deviation_time=0.0)),
    "slower correction (tau = 0.6 s)": (PRIOR_STD, dataclasses.replace(ROBOT_BELIEF, correction_time=0.6)),
    "open loop (no correction)": (PRIOR_STD, OnlineOptions()),
}


def at_times(t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """values (K,) at TIMES (the last one for times past the record)."""
    return np.array([values[min(int(np.searchsorted(t, s)), len(t) - 1)] for s in TIMES])


def replay(trial, prior_goal, prior_std, options: OnlineOptions, interval: float, model) -> np.ndarray:
    """The goal error (m) at TIMES of an online estimator fed the trial's handle every ``interval`` s."""
    record = trial.record
    estimator = OnlineGoalEstimator(model, np.r_[record.position[0], np.zeros(3)], prior_goal=prior_goal,
                                    prior_std=prior_std, options=options)
    errors = np.full(len(record.t), np.nan)
    due = interval
    for k, t in enumerate(record.t):
        if t > TIMES[-1] + interval:
            break
        if t >= due - 1e-9:
            estimator.update(t, record.position[k], record.velocity[k])
            due += interval
        if estimator.latest is not None:
            errors[k] = np.linalg.norm(estimator.latest.goal - record.goal)
    return at_times(record.t, errors)


def progress(trial, model, planner) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fraction of the reach done at TIMES: x-y of the hand, z of the hand, x-y and z of the model's plan."""
    record = trial.record
    start, offset = record.position[0], record.goal - record.position[0]
    plan = planner.solve(np.r_[start, np.zeros(model.state_size - 3)], record.goal).mean[:, :3] - start
    grid = model.h * np.arange(len(plan))
    hand = record.position - start

    def fraction(path, axes):
        return path[..., axes] @ offset[axes] / (offset[axes] @ offset[axes])
    planned = np.array([np.interp(s, grid, fraction(plan, [0, 1])) for s in TIMES]), np.array([np.interp(s, grid, fraction(plan, [2])) for s in TIMES])
    return at_times(record.t, fraction(hand, [0, 1])), at_times(record.t, fraction(hand, [2])), *planned


def table(header: str, rows: dict[str, np.ndarray], digits: int = 0) -> list[str]:
    lines = [f"| {header} | " + " | ".join(f"{s:g} s" for s in TIMES) + " |", "|---|" + "---|" * len(TIMES)]
    lines += [f"| {label} | " + " | ".join(f"{v:.{digits}f}" for v in values) + " |" for label, values in rows.items()]
    return lines + [""]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--trials", type=int, default=5, help="trials per goal (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=20, help="first person seed (default: %(default)s)")
    args = parser.parse_args()
    began = time.time()
    settings = {label: SyncSettings(goal=GOALS[label], trials=args.trials, seed=args.seed) for label in GOALS}
    setup = ScenarioSetup(next(iter(settings.values())))
    results = compare_sync_policies(settings, ["constant-velocity", "continuous"], setup)
    model = setup.model
    planner = OnlineGoalEstimator(model, np.zeros(model.state_size)).planner
    out = ["# Why the continuous goal estimate lags mid-reach\n",
           f"Measured by `PYTHONPATH=src python -m studies.why_does_the_online_estimate_lag_mid_reach.measure_online_lag --trials {args.trials} --seed {args.seed}` "
           f"(sync scenario, person seeds {args.seed}–{args.seed + args.trials - 1}, medians over the trials; "
           "{wall} s).\n"]
    for label, by_policy in results.items():
        s = settings[label]
        interval = s.update_interval
        errors = {name: 1e3 * np.median([at_times(tr.record.t, np.linalg.norm(
            np.where(np.isfinite(tr.record.goal_estimate), tr.record.goal_estimate, np.nan) - tr.record.goal, axis=1)) for tr in trials], axis=0)
            for name, trials in by_policy.items()}
        continuous = by_policy["continuous"]
        done = np.median([progress(tr, model, planner) for tr in continuous], axis=0)
        replays = {name: 1e3 * np.median([replay(tr, np.asarray(s.prior_goal), std, options, interval, model) for tr in continuous], axis=0)
                   for name, (std, options) in REPLAYS.items()}
        out += [f"## {label} (goal {np.round(s.goal, 2).tolist()} m)\n", "Goal error (mm) of the robots, closed loop:\n"]
        out += table("robot", errors)
        out += ["Fraction of the reach done (continuous robot's trials; the plan: the model's mean to the true goal):\n"]
        out += table("", {"hand x-y (person leads)": done[0], "hand z (robot leads)": done[1], "plan x-y": done[2], "plan z": done[3]}, 2)
        out += ["Goal error (mm) of the continuous robot's observations replayed into other estimators:\n"]
        out += table("estimator", replays)
        print("\n".join(out[-20:]), flush=True)
    text = "\n".join(out).replace("{wall}", f"{time.time() - began:.0f}")
    (DOCS / "online_lag.md").write_text(text)
    print(f"wrote {DOCS / 'online_lag.md'}")


if __name__ == "__main__":
    main()
