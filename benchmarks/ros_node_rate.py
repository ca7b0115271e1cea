"""The ROS 2 goal node's achieved rate and latency in replay (needs the 'ros' extra).

    .venv/bin/python benchmarks/ros_node_rate.py [--repeats 3] [--tracker-rate 100]

The hand: the Cartesian preset's plan from rest to (0.4, 0.25, -0.1) m, sampled by a tracker at
``--tracker-rate`` Hz (the plan's mean positions and velocities interpolated linearly between its 55 ms
steps), replayed through the node in-process (:mod:`comanip.ros.replay`) for the whole 2.75 s reach:

- lock step, every pose estimated (estimation_rate above the tracker's): each pose waits for the node to
  finish with it, so this is the node's throughput, estimates per second of wall time;
- real time, estimation_rate 20 Hz (the default) and the tracker's rate: the estimates the node published per
  second of wall time, and the poses it skipped (beyond the rate limit, or because an estimate was still
  running: the newest pose replaces a queued one).

Latency: wall time from publishing a pose to receiving the goal estimate made from it (the first estimate
of a reach, a cold start, apart). Rows print medians over ``--repeats`` replays; the node is built once per
replay (build time apart). Default budget max_wall_time 0.25 s.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from comanip.estimation.shared import estimation_planner
from comanip.multicomponent.transition_model import TransitionModel
from comanip.ros.replay import Replay
from comanip.ros.settings import NodeSettings

GOAL = np.array([0.4, 0.25, -0.1])


def tracker_samples(rate: float) -> tuple[np.ndarray, np.ndarray]:
    """Times (K,) s and states (K, 6) of the planned reach sampled at ``rate`` Hz."""
    plan = estimation_planner(NodeSettings().model()).solve(np.zeros(6), GOAL)
    times = np.arange(0.0, plan.t[-1], 1.0 / rate)
    return times, np.column_stack([np.interp(times, plan.t, plan.mean[:, k]) for k in range(6)])


def replay_once(settings: NodeSettings, transition: TransitionModel, times, states, speed: float | None) -> dict:
    t0 = time.perf_counter()
    with Replay(settings, transition) as replay:
        build = time.perf_counter() - t0
        recording = replay.run(times, states, speed)
    latencies = np.array([g[3] for g in recording.goals])
    last = recording.statuses[-1][3]
    return {"build_s": build, "wall_s": recording.wall_time, "estimates": len(recording.goals),
            "rate_hz": len(recording.goals) / recording.wall_time, "skipped": int(last["skipped"]),
            "cold_ms": 1e3 * latencies[0], "median_ms": 1e3 * np.median(latencies[1:]),
            "p95_ms": 1e3 * np.percentile(latencies[1:], 95), "goal_error_mm": 1e3 * np.linalg.norm(recording.goals[-1][1] - GOAL),
}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3, help="replays per mode (default: %(default)s)")
    parser.add_argument("--tracker-rate", type=float, default=100.0, help="hand poses per second (default: %(default)s)")
    args = parser.parse_args(argv)
    times, states = tracker_samples(args.tracker_rate)
    transition = TransitionModel()
    modes = [("lock step", None, 10 * args.tracker_rate), ("real time", 1.0, 20.0), ("real time", 1.0, 10 * args.tracker_rate)]
    print(f"{len(times)} hand poses at {args.tracker_rate:g} Hz over {times[-1]:.2f} s of reach; medians of {args.repeats} replays\n")
    print("| replay | estimation_rate (Hz) | estimates | achieved estimate rate (Hz) | skipped poses | latency median (ms) "
          "| latency p95 (ms) | first (cold) estimate (ms) | final goal error (mm) | node build (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, speed, rate in modes:
        settings = NodeSettings(estimation_rate=rate)
        runs = [replay_once(settings, transition, times, states, speed) for _ in range(args.repeats)]
        m = {key: float(np.median([r[key] for r in runs])) for key in runs[0]}
        shown = "every pose" if rate > args.tracker_rate else f"{rate:g}"
        print(f"| {name} | {shown} | {m['estimates']:.0f} | {m['rate_hz']:.1f} | {m['skipped']:.0f} | {m['median_ms']:.1f} "
              f"| {m['p95_ms']:.1f} | {m['cold_ms']:.0f} | {m['goal_error_mm']:.2g} | {m['build_s']:.1f} |")


if __name__ == "__main__":
    main()
