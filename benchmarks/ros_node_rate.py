"""The ROS 2 goal node's achieved rate and latency in replay (needs the 'ros' extra).

    .venv/bin/python benchmarks/ros_node_rate.py [--repeats 3] [--tracker-rate 100] [--rates 20,50] [--compare ../main]

The hand: the Cartesian preset's plan from rest to (0.4, 0.25, -0.1) m, sampled by a tracker at
``--tracker-rate`` Hz (the plan's mean positions and velocities interpolated linearly between its 55 ms
steps), replayed through the node for the whole 2.75 s reach:

- lock step, in-process, every pose estimated (estimation_rate above the tracker's): each pose waits for the
  node to finish with it (:mod:`comanip.ros.replay`), so this is the node's throughput, estimates per second of
  wall time;
- real time, two processes, as on a robot, at each of ``--rates`` (estimation_rate, Hz): the node started by
  ``python -m comanip ros`` in its own process, this script publishing the poses (stamped with the wall clock) and
  receiving the estimates over DDS.

For the real-time rows: the delivered estimation rate, (N - 1) / (last - first) over the input stamps of the N
estimates received (each goal message carries the stamp of the pose it was made from; the first three
estimates of a reach are 'uninformative', the hand not having moved yet, and not published), and that rate over
estimation_rate; the poses the node skipped (between the rate's due times, or because an estimate was still
running: the newest pose replaces a queued one); the rate and median latency the node reports in its own status
at the end of the reach (blank for a node without them). Latency: wall time from publishing a pose to receiving
the goal estimate made from it (the first estimate of a reach, a cold start, apart). Rows print medians over
``--repeats`` replays; the node is built once per replay (build time apart). ``--compare REF`` runs the real-time
rows a second time with the node from the checkout REF (its ``src`` on PYTHONPATH), the two nodes taking turns
replay by replay.
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

from comanip.estimation.model_reaches.estimation_planner import estimation_planner
from comanip.multicomponent.transition_model import TransitionModel
from comanip.ros.replay import Replay, private_domain
from comanip.ros.node_settings import NodeSettings

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


def two_processes(rate: float, times, states, src: Path | None = None, goal=GOAL, parameters: dict | None = None) -> dict:
    """Real time with the node in its own process (``python -m comanip ros``) at ``estimation_rate`` rate; ``src``:
    the checkout's source folder the node imports (None: this environment's); ``parameters``: further node
    parameters (name: value). Also returns ``begin`` (the wall time, s, of time 0 of ``times``), ``goals``
    (pose stamp s -> (wall time received s, goal (3,) m)), ``paths`` (pose stamp s -> wall time its predicted path
    was received, s), ``statuses`` (every status's values) and ``load`` (the machine's load average over the
    last minute as the poses began)."""
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TwistStamped
    from nav_msgs.msg import Path as PathMessage
    from rclpy.node import Node

    from comanip.ros.messages import seconds, stamp_of, status_values

    params = Path(tempfile.mkdtemp()) / "params.yaml"
    params.write_text("".join(f"{name}: {value}\n" for name, value in {"estimation_rate": rate, **(parameters or {})}.items()))
    t0 = time.time()
    domain = private_domain()
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    if src is not None:
        env["PYTHONPATH"] = str(src)
    node = subprocess.Popen([sys.executable, "-m", "comanip", "ros", "--params", str(params)], stderr=subprocess.DEVNULL, env=env)
    rclpy.init(domain_id=domain)
    player = Node("comanip_rate_benchmark")
    goals, paths, statuses = {}, {}, []
    player.create_subscription(PoseWithCovarianceStamped, "goal/estimate", lambda m: goals.setdefault(
        seconds(m.header.stamp), (time.time(), np.array([m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z]))), 50)
    player.create_subscription(PathMessage, "hand/predicted_path", lambda m: m.poses and paths.setdefault(
        seconds(m.poses[0].header.stamp), time.time()), 50)        # a forecast begins at the pose it was made from
    player.create_subscription(DiagnosticArray, "status", lambda m: statuses.append(status_values(m)), 50)
    pose_pub = player.create_publisher(PoseStamped, "hand/pose", 50)
    twist_pub = player.create_publisher(TwistStamped, "hand/twist", 50)
    try:
        while not statuses and time.time() - t0 < 120:
            rclpy.spin_once(player, timeout_sec=0.05)
        build = time.time() - t0
        load = os.getloadavg()[0]
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
        last = statuses[-1]
    finally:
        node.terminate()
        node.wait(timeout=20)
        player.destroy_node()
        rclpy.try_shutdown()
    stamps = sorted(goals)
    latencies = np.array([goals[s][0] - s for s in stamps])
    delivered = (len(stamps) - 1) / (stamps[-1] - stamps[0])
    return {"build_s": build, "estimates": len(goals), "rate_hz": delivered, "ratio": delivered / rate,
            "skipped": int(last["skipped"]), "cold_ms": 1e3 * latencies[0], "median_ms": 1e3 * np.median(latencies[1:]),
            "p95_ms": 1e3 * np.percentile(latencies[1:], 95), "goal_error_mm": 1e3 * np.linalg.norm(goals[stamps[-1]][1] - goal),
            "status_rate_hz": float(last.get("achieved_rate_hz", "nan")),
            "status_latency_ms": 1e3 * float(last.get("latency_median_s", "nan")), "begin": begin, "goals": goals,
            "paths": paths, "statuses": statuses, "load": load}


def lock_step(times, states, repeats: int, tracker_rate: float) -> str:
    settings = NodeSettings(estimation_rate=10 * tracker_rate)
    transition = TransitionModel()
    runs = [replay_once(settings, transition, times, states, None) for _ in range(repeats)]
    m = {key: float(np.median([r[key] for r in runs])) for key in runs[0]}
    return (f"| lock step, in-process | this | every pose | {m['estimates']:.0f} | {m['rate_hz']:.1f} | – | {m['skipped']:.0f} "
            f"| {m['median_ms']:.1f} | {m['p95_ms']:.1f} | {m['cold_ms']:.0f} | | | {m['goal_error_mm']:.2g} | {m['build_s']:.1f} |")


def _optional(value: float, digits: int) -> str:
    """A table cell: blank for NaN (a node that does not report the value)."""
    return "" if np.isnan(value) else f"{value:.{digits}f}"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=3, help="replays per row (default: %(default)s)")
    parser.add_argument("--tracker-rate", type=float, default=100.0, help="hand poses per second (default: %(default)s)")
    parser.add_argument("--rates", default="20,50", help="estimation rates (Hz) of the real-time rows (default: %(default)s)")
    parser.add_argument("--compare", type=Path, default=None, help="another checkout whose node runs the real-time rows too")
    parser.add_argument("--no-lock-step", action="store_true", help="only the real-time rows")
    args = parser.parse_args(argv)
    times, states = tracker_samples(args.tracker_rate)
    print(f"{len(times)} hand poses at {args.tracker_rate:g} Hz over {times[-1]:.2f} s of reach; medians of {args.repeats} replays; "
          f"load average {' '.join(f'{v:.2f}' for v in os.getloadavg())}\n")
    print("| replay | code | estimation_rate (Hz) | estimates | delivered rate (Hz) | delivered / configured | skipped poses "
          "| latency median (ms) | latency p95 (ms) | first (cold) estimate (ms) | status: rate (Hz) | status: latency median (ms) "
          "| final goal error (mm) | node build (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    if not args.no_lock_step:
        print(lock_step(times, states, args.repeats, args.tracker_rate), flush=True)
    codes = {"this": None} if args.compare is None else {"new": None, "ref": args.compare.resolve() / "src"}
    for rate in (float(r) for r in args.rates.split(",")):
        runs = {label: [] for label in codes}
        for _ in range(args.repeats):
            for label, src in codes.items():
                runs[label].append(two_processes(rate, times, states, src))
        for label, results in runs.items():
            m = {key: float(np.median([r[key] for r in results])) for key in results[0] if key not in ("begin", "goals", "paths", "statuses", "load")}
            print(f"| real time, two processes | {label} | {rate:g} | {m['estimates']:.0f} | {m['rate_hz']:.2f} | {m['ratio']:.3f} "
                  f"| {m['skipped']:.0f} | {m['median_ms']:.1f} | {m['p95_ms']:.1f} | {m['cold_ms']:.0f} "
                  f"| {_optional(m['status_rate_hz'], 2)} | {_optional(m['status_latency_ms'], 1)} "
                  f"| {m['goal_error_mm']:.2g} | {m['build_s']:.1f} |", flush=True)
    print(f"\nload average at end {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
