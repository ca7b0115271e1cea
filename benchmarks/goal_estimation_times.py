"""Goal-estimation times: the one-shot estimate (`GoalEstimator.estimate`) against the online estimator
(`OnlineGoalEstimator.update`), cold and warm, on the same noisy reaches, in the same run.

    .venv/bin/python benchmarks/goal_estimation_times.py [--reaches 20] [--only cartesian,planar] [--markdown]

``--markdown`` prints the block ``online-estimation-speed`` of docs/results/speed.md (tools/regenerate_results.py) instead.

Each reach goes from rest to a goal 0.15–0.45 m away in a random direction, sampled from the model's own
noisy dynamics (open loop) and observed every 10 ms from 10 ms to 0.5 s with the default observation noise
(1 mm, 1 cm/s). Both estimators get the same prior: a goal 0.1 m off the true one in a random direction, with
prior_std 0.1 m. Rows (medians over reaches or updates; wall time, and process CPU time, which the other jobs
on a shared machine inflate less):

- one-shot cold: `estimate` from the state observed at 0.2 s, no warm start (its own search);
- one-shot warm: from the state observed 10 ms later, warm-started from that cold estimate;
- online first (cold): the first update whose observations show movement (the estimator's cold start);
- online update (warm): every later update, each using all observations so far;
- ", corrected": the same with the options of a person who corrects deviations from their plan
  (comanip.estimation.online.corrected_deviation, as the sync scenario's continuous policy uses them).

The online estimator's reach family is built once per model and width (in the constructor, timed apart
as "build"); the one-shot estimator's compiled planner likewise.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import comanip
from comanip.belief import sample_trajectories
from comanip.estimation import GoalEstimator, OnlineGoalEstimator, OnlineOptions
from comanip.estimation.online.corrected_deviation import CORRECTION_TIME, DEVIATION_TIME

OBSERVATION_STD = (1e-3, 1e-2)
PRIOR_OFFSET = 0.1   # m, also the prior's std


def clocked(call):
    """(result, wall s, CPU s) of call()."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = call()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def reaches(model, planner, count: int, rng):
    """(goal, prior goal, observation times (K,), observed states (K, 2n)) of ``count`` noisy reaches from rest at 0."""
    n, h = model.n, model.h
    times = np.arange(0.01, 0.5 + 1e-9, 0.01)
    noise = np.r_[np.full(n, OBSERVATION_STD[0]), np.full(n, OBSERVATION_STD[1])]
    for _ in range(count):
        u = rng.normal(size=model.d)
        goal = rng.uniform(0.15, 0.45) * u / np.linalg.norm(u)
        plan = planner.solve(np.zeros(model.state_size), goal)
        states = sample_trajectories(model.body, h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0][:, :2 * n]
        steps = np.minimum((times / h).astype(int), model.H - 1)
        fraction = (times / h - steps)[:, None]
        observed = (1 - fraction) * states[steps] + fraction * states[steps + 1] + rng.normal(size=(len(times), 2 * n)) * noise
        offset = rng.normal(size=model.d)
        yield goal, goal + PRIOR_OFFSET * offset / np.linalg.norm(offset), times, observed


def run_preset(preset: str, count: int) -> list[tuple]:
    model = comanip.presets.load(preset)
    n = model.n
    start = np.zeros(model.state_size)
    one_shot, one_shot_build, _ = clocked(lambda: GoalEstimator(model))
    first, online_build, _ = clocked(lambda: OnlineGoalEstimator(model, start))
    rng = np.random.default_rng(0)
    variants = {"": OnlineOptions(), ", corrected": OnlineOptions(correction_time=CORRECTION_TIME, deviation_time=DEVIATION_TIME)}
    rows = {key: [] for key in ("one-shot cold", "one-shot warm")}
    for suffix in variants:
        rows[f"online first (cold){suffix}"], rows[f"online update (warm){suffix}"] = [], []
    for goal, prior, times, observed in reaches(model, one_shot.planner, count, rng):
        k = int(np.argmin(np.abs(times - 0.2)))
        cold, wall, cpu = clocked(lambda: one_shot.estimate(start, observed[k], times[k], prior, prior_std=PRIOR_OFFSET))
        rows["one-shot cold"].append((wall, cpu, cold.success))
        warm, wall, cpu = clocked(lambda: one_shot.estimate(start, observed[k + 1], times[k + 1], prior, prior_std=PRIOR_OFFSET,
                                                            warm_start=cold))
        rows["one-shot warm"].append((wall, cpu, warm.success))
        for suffix, options in variants.items():
            online = OnlineGoalEstimator(model, start, prior_goal=prior, prior_std=PRIOR_OFFSET, options=options)
            started = False
            for t, y in zip(times, observed):
                estimate, wall, cpu = clocked(lambda: online.update(t, y[:n], y[n:]))
                if estimate.status == "uninformative" and not started:
                    continue
                rows[f"online update (warm){suffix}" if started else f"online first (cold){suffix}"].append((wall, cpu, estimate.success))
                started = True
    table = [(preset, "build", 1e3 * one_shot_build, None, None, 1, "one-shot: compiled planner"),
             (preset, "build", 1e3 * online_build, None, None, 1, "online: reach family "
              f"({len(first.family.distances)} plans, interpolation error {1e3 * first.family.interpolation_error:.3f} mm)")]
    for name, values in rows.items():
        wall, cpu, success = (np.array(v) for v in zip(*values))
        table.append((preset, name, 1e3 * np.median(wall), 1e3 * np.percentile(wall, 90), 1e3 * np.median(cpu), len(wall),
                      f"success {success.mean():.2f}"))
    return table


def markdown_block(tables: dict[str, list[tuple]], reaches: int) -> str:
    """The README's table: per preset the one-shot and online medians (ms), the online p90, the family's build."""
    lines = ["| preset | one-shot `estimate`, cold / warm | online, first (cold) / update (warm) | online family, built once |",
             "|---|---|---|---|"]
    for preset, table in tables.items():
        rows = {what: (median, p90) for _, what, median, p90, *_ in table if what != "build"}
        build = [median for _, what, median, _, _, _, note in table if what == "build" and note.startswith("online")][0]
        (cold, _), (warm, _) = rows["one-shot cold"], rows["one-shot warm"]
        (first, first_p90), (update, update_p90) = rows["online first (cold)"], rows["online update (warm)"]
        lines.append(f"| {preset} | {cold:.0f} / {warm:.0f} ms | **{first:.1f} / {update:.1f} ms** (p90 {first_p90:.1f} / "
                     f"{update_p90:.1f}) | {build / 1e3:.1f} s |")
    lines += ["", f"({reaches} noisy reaches per preset observed at 100 Hz, medians of one run of "
              "`benchmarks/goal_estimation_times.py --markdown`; the one-shot rows from the state at 0.2 s, warm from "
              "the estimate 10 ms earlier; both with a prior 0.1 m off and `prior_std=0.1`.)"]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reaches", type=int, default=20, help="noisy reaches per preset (default: %(default)s)")
    parser.add_argument("--only", default="cartesian,planar", help="comma-separated presets (default: %(default)s)")
    parser.add_argument("--markdown", action="store_true", help="print the README's block instead")
    args = parser.parse_args()
    tables = {preset: run_preset(preset, args.reaches) for preset in args.only.split(",")}
    if args.markdown:
        print(markdown_block(tables, args.reaches), end="")
        return
    print("| preset | estimate | median wall (ms) | p90 wall (ms) | median CPU (ms) | count | note |")
    print("|---|---|---|---|---|---|---|")
    for table in tables.values():
        for name, what, median, p90, cpu, count, note in table:
            cells = [f"{median:.1f}", "" if p90 is None else f"{p90:.1f}", "" if cpu is None else f"{cpu:.1f}"]
            print(f"| {name} | {what} | {' | '.join(cells)} | {count} | {note} |", flush=True)


if __name__ == "__main__":
    main()
