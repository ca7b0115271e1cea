"""The ROS 2 goal node's achieved rate and latency in replay (needs the 'ros' extra).

    .venv/bin/python benchmarks/ros_node_rate.py [--repeats 3] [--speeds 1,5]

The hand: the Cartesian preset's plan from rest to (0.4, 0.25, -0.1) m, its mean states on the model's own
grid (h = 55 ms, 18.2 poses/s: today's estimator matches an observation to the grid step before it, so poses
between steps would be read as the wrong step; the online estimator takes any time), replayed through the
node in-process (:mod:`comanip.ros.replay`) for the whole 2.75 s reach, every pose sent to the estimator
(estimation_rate 1000 Hz):

- lock step: each pose waits for the node to finish with it: the node's throughput, estimates per second of
  wall time;
- at ``--speeds`` times real time (1: real time; 5: 91 poses/s): the estimates the node published per
  second and the poses it skipped because a solve was still running (the newest pose replaces a queued one).

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


def planned_reach() -> tuple[np.ndarray, np.ndarray]:
    """Times (H+1,) s and mean states (H+1, 6) of the planned reach."""
    plan = estimation_planner(NodeSettings().model()).solve(np.zeros(6), GOAL)
    return plan.t, plan.mean


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
    parser.add_argument("--speeds", default="1,5", help="replay speeds, multiples of real time (default: %(default)s)")
    args = parser.parse_args(argv)
    times, states = planned_reach()
    transition = TransitionModel()
    settings = NodeSettings(estimation_rate=1000.0)
    modes = [("lock step", None)] + [(f"{float(v):g}× real time", float(v)) for v in args.speeds.split(",")]
    print(f"{len(times)} hand poses over {times[-1]:.2f} s of reach; medians of {args.repeats} replays\n")
    print("| replay | poses/s sent | estimates | achieved estimate rate (Hz) | skipped poses | latency median (ms) "
          "| latency p95 (ms) | first (cold) estimate (ms) | final goal error (mm) | node build (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, speed in modes:
        runs = [replay_once(settings, transition, times, states, speed) for _ in range(args.repeats)]
        m = {key: float(np.median([r[key] for r in runs])) for key in runs[0]}
        sent = "as handled" if speed is None else f"{speed / (times[1] - times[0]):.0f}"
        print(f"| {name} | {sent} | {m['estimates']:.0f} | {m['rate_hz']:.1f} | {m['skipped']:.0f} | {m['median_ms']:.1f} "
              f"| {m['p95_ms']:.1f} | {m['cold_ms']:.0f} | {m['goal_error_mm']:.2g} | {m['build_s']:.1f} |")


if __name__ == "__main__":
    main()
