"""Does the model's reach at the person's pace earn its time in an update?

    PYTHONPATH=src python -m studies.does_the_person_pace_explanation_earn_its_time.measure_person_pace [--limit 60]

The online estimator with ``timing="paced"`` (the chain with the model's reach at the person's pace, explaining the
hand and vetoing the model at its own pace) against ``timing="estimated"`` (the chain without it), each update of
each movement run by both, on: the recorded arm reaches' development split (``../shared/data/arm_reaches``,
streamed at 125 Hz), the ``cursory`` mouse movements' development split (the ``data`` extra), and reaches sampled
from the ``arm`` and ``planar`` presets' own noise played at ×0.7, ×1 and ×1.5 the model's pace (a person who moves
as the model does at their own pace). Printed per source and chain: the share of updates whose estimate the
person's pace gives, the endpoint error / D (median) at 25 / 50 / 75 / 90 % of MT, the forecast's error / D
(median) at +0.1 / +0.2 / +0.3 s from 25 and 50 % of MT, the update time (median / p95, ms), and the largest
difference between the two chains' goals over every update (m): zero where the person's pace never gives an
estimate nor vetoes.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import comanip
from benchmarks.real_people import ARMS
from comanip.belief import sample_trajectories
from comanip.estimation import OnlineOptions
from comanip.recordings import load_cursory, load_tathum, recording_from_samples

FRACTIONS = (0.25, 0.5, 0.75, 0.9)
FROM, LEADS = (0.25, 0.5), (0.1, 0.2, 0.3)
PACES = (0.7, 1.0, 1.5)
TIMINGS = ("paced", "estimated")


def paced_recordings(preset: str, pace: float, count: int, seed: int):
    """Reaches sampled from ``preset``'s own noise (open loop) from rest to goals 0.1–0.6 m away in random directions,
    played at ``pace`` times the model's duration, 0.1 s at rest before each, as recordings at 100 Hz."""
    model = comanip.presets.load(preset)
    planner = comanip.Planner(model)
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        direction = rng.normal(size=model.d)
        goal = rng.uniform(0.1, 0.6) * direction / np.linalg.norm(direction)
        plan = planner.solve(np.zeros(model.state_size), goal, model.width)
        states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
        rest = np.repeat(states[:1, :model.n], 10, axis=0)
        t = np.r_[np.arange(-10, 0) * model.h, pace * plan.t] + 10 * model.h
        out.append(recording_from_samples(f"{preset}/x{pace:g}/{k}", t, np.r_[rest, states[:, :model.n]], step=0.01,
                                          target=goal))
    return out


def run(model, recording, timing: str):
    """Per update: (time s, estimate, update wall time s) of one chain over one movement."""
    estimator = comanip.OnlineGoalEstimator(model, np.r_[recording.position[0], np.zeros(model.state_size - model.n)],
                                            options=OnlineOptions(timing=timing))
    trace = []
    for k in range(len(recording.t)):
        begin = time.perf_counter()
        estimate = estimator.update(float(recording.t[k]), recording.position[k], recording.velocity[k])
        trace.append((float(recording.t[k]), estimate, time.perf_counter() - begin))
    return trace


def scores(recording, trace) -> dict:
    """Endpoint errors / D at FRACTIONS, forecast errors / D at (FROM, LEADS), the share of updates the person's pace
    gives, and the update times (s)."""
    D = recording.distance
    endpoint = [float(np.linalg.norm(trace[recording.seen_until(f) - 1][1].goal - recording.end)) / D for f in FRACTIONS]
    ahead = []
    for f in FROM:
        t_now, estimate, _ = trace[recording.seen_until(f) - 1]
        truth = np.array([recording.position_at(t_now + s) for s in LEADS])
        ahead += list(np.linalg.norm(estimate.forecast.at(t_now + np.array(LEADS)).position - truth, axis=1) / D)
    paced = np.mean(["person's pace" in estimate.message.split("; ")[-1] and estimate.success for _, estimate, _ in trace])
    return {"endpoint": endpoint, "ahead": ahead, "paced": float(paced), "times": [seconds for _, _, seconds in trace[1:]]}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--limit", type=int, default=60, help="movements per recorded source")
    parser.add_argument("--count", type=int, default=20, help="reaches per preset and pace")
    args = parser.parse_args(argv)
    sources = []
    if ARMS.is_dir():
        sources.append(("recorded arms", "arm", [trial.streamed_recording() for trial in load_tathum(ARMS)[:args.limit]]))
    try:
        sources.append(("recorded mouse", "planar", load_cursory("development")[:args.limit]))
    except ImportError:
        print("no cursory data (the 'data' extra): the mouse movements are left out")
    for preset in ("arm", "planar"):
        for pace in PACES:
            sources.append((f"{preset} preset at ×{pace:g}", preset, paced_recordings(preset, pace, args.count, seed=3)))
    header = ("| source | chain | person's pace gives | endpoint 25 / 50 / 75 / 90 % | forecast from 25 %: +0.1 / +0.2 / +0.3 s "
              "| from 50 % | update median / p95 (ms) | largest goal difference (m) |")
    print(header)
    print("|---|---|---|---|---|---|---|---|")
    for label, preset, recordings in sources:
        model = comanip.presets.load(preset)
        rows, difference = {timing: [] for timing in TIMINGS}, 0.0
        for recording in recordings:
            traces = {timing: run(model, recording, timing) for timing in TIMINGS}
            for timing in TIMINGS:
                rows[timing].append(scores(recording, traces[timing]))
            difference = max(difference, max(float(np.linalg.norm(a[1].goal - b[1].goal))
                                             for a, b in zip(*traces.values())))
        for timing in TIMINGS:
            chosen = rows[timing]
            endpoint = np.median([r["endpoint"] for r in chosen], axis=0)
            ahead = np.median([r["ahead"] for r in chosen], axis=0)
            times = 1e3 * np.concatenate([r["times"] for r in chosen])
            print(f"| {label} ({len(recordings)}) | {timing} | {100 * np.mean([r['paced'] for r in chosen]):.0f} % | "
                  + " / ".join(f"{e:.3f}" for e in endpoint) + " | " + " / ".join(f"{e:.3f}" for e in ahead[:3]) + " | "
                  + " / ".join(f"{e:.3f}" for e in ahead[3:]) + f" | {np.median(times):.2f} / {np.percentile(times, 95):.2f} | "
                  + (f"{difference:.2g} |" if timing == TIMINGS[-1] else " |"), flush=True)


if __name__ == "__main__":
    main()
