"""Update times of the online estimator with its forecast of the hand, and of the forecast alone.

    .venv/bin/python benchmarks/forecast_times.py [--reaches 40] [--presets arm,human_cartesian,planar] [--repeats 3] [--stages]

Each preset's estimator follows reaches sampled from the model's own noise (open loop) from rest to goals
0.1–0.6 m away in random directions, observed at 125 Hz, with the shipped people model; the recorded arm
reaches (``../shared/data/arm_reaches``, when beside the clone) are streamed as a tracker delivers them. Every
update is timed (wall and process CPU time: the other jobs on a shared machine inflate the CPU time less), and
the forecast alone (``continued_reach`` on the same inputs) right after it. Printed: median, p95 and largest per
preset and source, and the slowest updates. ``--stages`` adds where an update spends its time: each explanation of
the estimator's chain (the time of its ``explain``, in the updates that ask it) and the rest of the update (the
estimate from the explanation's answer, the smoothed goal, the forecast), each stage's median and p95 over the updates
that run it and its share of all update time.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

ARMS = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"


def sampled_reaches(model, count: int, rng):
    """(t, positions, velocities) of ``count`` reaches from the model's own noise, at 125 Hz."""
    import comanip
    from comanip.belief import sample_trajectories
    planner = comanip.Planner(model)
    reaches = []
    for _ in range(count):
        direction = rng.normal(size=model.d)
        goal = rng.uniform(0.1, 0.6) * direction / np.linalg.norm(direction)
        plan = planner.solve(np.zeros(model.state_size), goal, model.width)
        states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
        t = np.arange(0.008, plan.t[-1], 0.008)
        position = np.array([np.interp(t, plan.t, states[:, k]) for k in range(model.n)]).T
        velocity = np.array([np.interp(t, plan.t, states[:, model.n + k]) for k in range(model.n)]).T
        reaches.append((t, position, velocity))
    return reaches


def recorded_reaches(limit: int):
    from comanip.recordings import load_tathum
    return [(r.t, r.position, r.velocity) for r in (trial.streamed_recording() for trial in load_tathum(ARMS)[:limit])]


def recorded_mouse_movements(limit: int):
    """The first ``limit`` movements of the ``cursory`` development split (the ``data`` extra), or [] without it."""
    try:
        from comanip.recordings import load_cursory
        recordings = load_cursory("development")[:limit]
    except ImportError:
        return []
    return [(r.t, r.position, r.velocity) for r in recordings]


STAGE_NAMES = {"HandAtRest": "the hand at rest", "Vetoed": "the model at its own pace, with its vetoes",
               "ModelAtOwnPace": "the model at its own pace", "ModelAtPersonPace": "the model at the person's pace",
               "RecordedPeople": "recorded people (the people model)"}
"""Readable names of the default chain's explanations (others keep their class name)."""
REST = "the rest (estimate, smoothing, forecast)"
"""The stage of an update outside its explanations."""


def timed_stage(explanation, stage_times: list):
    """Make ``explanation.explain`` append its wall time (s) to ``stage_times`` as (stage name, s)."""
    explain = explanation.explain
    name = STAGE_NAMES.get(type(explanation).__name__, type(explanation).__name__)

    def timed(hand, latest):
        begin = time.perf_counter()
        explained = explain(hand, latest)
        stage_times.append((name, time.perf_counter() - begin))
        return explained
    explanation.explain = timed


def timed_updates(model, reaches, repeats: int, stages: dict | None = None):
    """[(wall s, cpu s, forecast wall s, update index, its longest stage or "")] of every update of every reach,
    ``repeats`` times; with ``stages`` (a dict), each stage's wall times (s) are appended to ``stages[name]`` ("the
    rest": the update less its explanations)."""
    import comanip
    from comanip.estimation.hand_forecast import continued_reach
    out = []
    for _ in range(repeats):
        for t, position, velocity in reaches:
            estimator = comanip.OnlineGoalEstimator(model, np.r_[position[0], np.zeros(model.state_size - model.n)])
            asked: list = []
            if stages is not None:
                for explanation in estimator.explanations:
                    timed_stage(explanation, asked)
            for k in range(len(t)):
                asked.clear()
                wall, cpu = time.perf_counter(), time.process_time()
                estimate = estimator.update(float(t[k] - t[0]), position[k], velocity[k])
                wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
                longest = ""
                if stages is not None:
                    parts = asked + [(REST, wall - sum(seconds for _, seconds in asked))]
                    for name, seconds in parts:
                        stages.setdefault(name, []).append(seconds)
                    name, seconds = max(parts, key=lambda pair: pair[1])
                    longest = f"{name} {1e3 * seconds:.1f} ms"
                forecast = estimate.forecast
                begin = time.perf_counter()
                continued_reach(estimator.family, estimator.start_position, estimate.t_obs,
                                position[k], velocity[k], estimate.goal, estimate.goal_covariance, forecast.stop_time)
                out.append((wall, cpu, time.perf_counter() - begin, k, longest))
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reaches", type=int, default=40)
    parser.add_argument("--presets", default="arm,human_cartesian,planar")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--stages", action="store_true", help="also print where an update spends its time")
    args = parser.parse_args(argv)
    import comanip
    rng = np.random.default_rng(0)
    print("| preset | reaches | updates | update wall median / p95 / largest (ms) | CPU median / p95 (ms) | "
          "forecast alone median / p95 (ms) |")
    print("|---|---|---|---|---|---|")
    slowest, breakdowns = [], []
    for name in args.presets.split(","):
        model = comanip.presets.load(name)
        sources = [("sampled", sampled_reaches(model, args.reaches, rng))]
        if name == "arm" and ARMS.is_dir():
            sources.append(("recorded arms", recorded_reaches(args.reaches)))
        if model.d == 2 and (mouse := recorded_mouse_movements(args.reaches)):
            sources.append(("recorded mouse", mouse))
        for source, reaches in sources:
            stages = {} if args.stages else None
            updates = timed_updates(model, reaches, args.repeats, stages)
            rows = np.array([update[:4] for update in updates])
            if stages is not None:
                breakdowns.append((f"{name} ({source})", stages, 1e3 * rows[:, 0].sum()))
            wall, cpu, alone = 1e3 * rows[:, 0], 1e3 * rows[:, 1], 1e3 * rows[:, 2]
            print(f"| {name} ({source}) | {len(reaches)} | {len(rows)} | {np.median(wall):.2f} / {np.percentile(wall, 95):.2f} / "
                  f"{wall.max():.1f} | {np.median(cpu):.2f} / {np.percentile(cpu, 95):.2f} | "
                  f"{np.median(alone):.2f} / {np.percentile(alone, 95):.2f} |", flush=True)
            worst = np.argsort(wall)[-3:][::-1]
            slowest += [f"{name} ({source}): {wall[i]:.1f} ms at update {int(rows[i, 3])}"
                        + (f" ({updates[i][4]})" if updates[i][4] else "") for i in worst]
    print("\nSlowest updates: " + "; ".join(slowest))
    if breakdowns:
        print("\nWhere an update spends its time (wall; each stage over the updates that run it):\n\n"
              "| preset | stage | updates | median / p95 (ms) | share of all update time |\n|---|---|---|---|---|")
        for label, stages, total_ms in breakdowns:
            for stage, seconds in stages.items():
                ms = 1e3 * np.array(seconds)
                print(f"| {label} | {stage} | {len(ms)} | {np.median(ms):.2f} / {np.percentile(ms, 95):.2f} | "
                      f"{100 * ms.sum() / total_ms:.0f} % |")


if __name__ == "__main__":
    main()
