"""The ROS 2 goal node's achieved rate and latency in replay (needs the 'ros' extra).

    .venv/bin/python benchmarks/ros_node_rate.py [--repeats 3] [--tracker-rate 100]

The hand: the Cartesian preset's plan from rest to (0.4, 0.25, -0.1) m, sampled by a tracker at
``--tracker-rate`` Hz (the plan's mean positions and velocities interpolated linearly between its 55 ms
steps), replayed through the node in-process (:mod:`comanip.ros.replay`) for the whole 2.75 s reach:

- lock step, every pose estimated (estimation_rate above the tracker's): each pose waits for the node to
  finish with it, so this is the node's throughput, estimates per second of wall time;
- real time, two processes, as on a robot: the node started by ``comanip ros`` in its own process, this
  script publishing the poses (stamped with the wall clock) and receiving the estimates over DDS.

For the real-time rows, at estimation_rate 20 Hz (the default) and at every pose: the estimates the node
published per second of wall time, the poses it skipped (beyond the rate limit, or because an estimate was
still running: the newest pose replaces a queued one). (The replay's own real-time mode, ``--speed 1``, puts
the player, its /clock and the node in one Python process and one executor; on this loaded 2-core machine
at 100 poses/s that process falls behind by a second, so it is not used for rates here.)

Latency: wall time from publishing a pose to receiving the goal estimate made from it (the first estimate
of a reach, a cold start, apart; in two processes, receipt time minus the pose's wall-clock stamp). Rows print medians over ``--repeats`` replays; the node is built once per
replay (build time apart). Default budget max_wall_time 0.25 s.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from comanip.estimation.shared import estimation_planner
from comanip.multicomponent.transition_model import TransitionModel
from comanip.ros.replay import Replay, private_domain
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
        last = replay.node.status()[1]
    latencies = np.array([g[3] for g in recording.goals])
    return {"build_s": build, "wall_s": recording.wall_time, "estimates": len(recording.goals),
            "rate_hz": len(recording.goals) / recording.wall_time, "skipped": int(last["skipped"]), "lost": recording.lost,
            "cold_ms": 1e3 * latencies[0], "median_ms": 1e3 * np.median(latencies[1:]),
            "p95_ms": 1e3 * np.percentile(latencies[1:], 95), "goal_error_mm": 1e3 * np.linalg.norm(recording.goals[-1][1] - GOAL),
}


def two_processes(rate: float, times, states) -> dict:
    """Real time with the node in its own process (``python -m comanip.ros``) at ``estimation_rate`` rate."""
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TwistStamped
    from rclpy.node import Node

    from comanip.ros.messages import seconds, stamp_of, status_values

    params = Path(tempfile.mkdtemp()) / "params.yaml"
    params.write_text(f"estimation_rate: {rate}\n")
    t0 = time.time()
    domain = private_domain()
    node = subprocess.Popen([sys.executable, "-m", "comanip.ros", "--params", str(params)], stderr=subprocess.DEVNULL,
                            env={**os.environ, "ROS_DOMAIN_ID": str(domain)})
    rclpy.init(domain_id=domain)
    player = Node("comanip_rate_benchmark")
    goals, statuses = {}, []
    player.create_subscription(PoseWithCovarianceStamped, "goal/estimate", lambda m: goals.setdefault(
        seconds(m.header.stamp), (time.time(), np.array([m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z]))), 50)
    player.create_subscription(DiagnosticArray, "status", lambda m: statuses.append(status_values(m)), 50)
    pose_pub = player.create_publisher(PoseStamped, "hand/pose", 50)
    twist_pub = player.create_publisher(TwistStamped, "hand/twist", 50)
    try:
        while not statuses and time.time() - t0 < 120:
            rclpy.spin_once(player, timeout_sec=0.05)
        build = time.time() - t0
        begin = time.time()
        for t, state in zip(times, states):
            while (wait := begin + t - time.time()) > 0:
                rclpy.spin_once(player, timeout_sec=wait)
            stamp = stamp_of(time.time())
            twist, pose = TwistStamped(), PoseStamped()
            twist.header.stamp = pose.header.stamp = stamp
            twist.header.frame_id = pose.header.frame_id = "world"
            twist.twist.linear.x, twist.twist.linear.y, twist.twist.linear.z = (float(v) for v in state[3:])
            pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = (float(v) for v in state[:3])
            twist_pub.publish(twist)
            pose_pub.publish(pose)
        end = time.time() + 1.0
        while time.time() < end:
            rclpy.spin_once(player, timeout_sec=0.01)
        wall = max(received for received, _ in goals.values()) - begin
        last = statuses[-1]
    finally:
        node.terminate()
        node.wait(timeout=20)
        player.destroy_node()
        rclpy.try_shutdown()
    stamps = sorted(goals)
    latencies = np.array([goals[s][0] - s for s in stamps])
    return {"build_s": build, "wall_s": wall, "estimates": len(goals), "rate_hz": len(goals) / wall, "skipped": int(last["skipped"]),
            "lost": float("nan"), "cold_ms": 1e3 * latencies[0], "median_ms": 1e3 * np.median(latencies[1:]),
            "p95_ms": 1e3 * np.percentile(latencies[1:], 95), "goal_error_mm": 1e3 * np.linalg.norm(goals[stamps[-1]][1] - GOAL)}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3, help="replays per mode (default: %(default)s)")
    parser.add_argument("--tracker-rate", type=float, default=100.0, help="hand poses per second (default: %(default)s)")
    args = parser.parse_args(argv)
    times, states = tracker_samples(args.tracker_rate)
    transition = TransitionModel()
    every = 10 * args.tracker_rate
    modes = [("lock step, in-process", None, every), ("real time, two processes", "processes", 20.0),
             ("real time, two processes", "processes", every)]
    print(f"{len(times)} hand poses at {args.tracker_rate:g} Hz over {times[-1]:.2f} s of reach; medians of {args.repeats} replays\n")
    print("| replay | estimation_rate (Hz) | estimates | achieved estimate rate (Hz) | skipped poses | lost poses | latency median (ms) "
          "| latency p95 (ms) | first (cold) estimate (ms) | final goal error (mm) | node build (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, speed, rate in modes:
        settings = NodeSettings(estimation_rate=rate)
        if speed == "processes":
            runs = [two_processes(rate, times, states) for _ in range(args.repeats)]
        else:
            runs = [replay_once(settings, transition, times, states, speed) for _ in range(args.repeats)]
        m = {key: float(np.median([r[key] for r in runs])) for key in runs[0]}
        lost = "–" if np.isnan(m["lost"]) else f"{m['lost']:.0f}"
        shown = "every pose" if rate > args.tracker_rate else f"{rate:g}"
        print(f"| {name} | {shown} | {m['estimates']:.0f} | {m['rate_hz']:.1f} | {m['skipped']:.0f} | {lost} | {m['median_ms']:.1f} "
              f"| {m['p95_ms']:.1f} | {m['cold_ms']:.0f} | {m['goal_error_mm']:.2g} | {m['build_s']:.1f} |")


if __name__ == "__main__":
    main()
