"""The ROS 2 goal node live at a tracker's rate for minutes: every pose answered in time, no growth (needs 'ros').

    .venv/bin/python benchmarks/node_at_tracker_rate.py [--minutes 10] [--rate 250] [--twists] [--compare REF]
                                                        [--markdown] [--out DIR]

The node runs in its own process as a user starts it, ``python -m comanip ros --preset arm --estimation-rate RATE``;
this script is the tracker, in another process: the development arm reaches of TAT-HUM (``../shared``) joined back
to back with their rests (as ``reach_loop.py`` joins them), repeated to fill ``--minutes``, published as
``PoseStamped`` at ``--rate`` Hz stamped with the wall clock (the node derives the velocity from the poses), and
with ``--twists`` a ``TwistStamped`` of the same stamp before each pose. Per minute of the run: the latency from
publishing a pose to receiving the goal that answers it (median, p95, p99, largest), the share of the poses of
the hand's movements (each recorded reach's onset to its end) that got an answer, the same from each reach's first
goal on (the reach found and its estimate past the prior) and the share of those answered within the next pose's
period, the first goal of each reach apart (a reach's first update gets its lead too), and the
node's resident memory at the minute's end. ``--compare REF`` runs the node of the checkout REF (its ``src`` on
PYTHONPATH) too, the two taking turns every ``--turn`` minutes, both fed twists (a node that cannot derive the
velocity rejects poses without one).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from reach_loop import ARMS, joined_stream  # noqa: E402  (the joined stream beside this script)
from solve_times import reference_source  # noqa: E402

from comanip.recordings import load_tathum  # noqa: E402

GAP = 0.1
"""A goal more than this (s) after the goal before it is the first goal of a reach."""


def tracker_stream(minutes: float, rate: float):
    """Times (K,) s and positions (K, 3) m of the joined development reaches, repeated to ``minutes``, at ``rate`` Hz,
    and the (onset, end) times (s) of the reaches in it."""
    trials = load_tathum(ARMS)
    tracked, reaches = joined_stream(trials, 0.5, 0.2)
    repeats = int(np.ceil(60.0 * minutes / tracked.t[-1]))
    tracked, reaches = joined_stream(trials * repeats, 0.5, 0.2)
    t, position, _ = tracked.stream(rate_hz=rate)
    keep = (t <= 60.0 * minutes) & np.all(np.isfinite(position), axis=1)
    return t[keep], position[keep], [(r.onset, r.end_time) for r in reaches if r.end_time <= 60.0 * minutes]


def nanoseconds(stamp) -> int:
    """A builtin_interfaces/Time as integer nanoseconds: a goal is matched to its pose by this exact key (float seconds
    near 1.8e9 s rounded on one side by Python and on the other by NumPy can differ in their last digit)."""
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def resident_mb(pid: int) -> float:
    """The process's resident memory (MB), from /proc (NaN where there is none)."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return float(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


def live_run(t, position, rate: float, twists: bool, src: Path | None, label: str) -> dict:
    """The node in its own process fed the poses in real time: per pose its publication wall time (s) and the
    wall time its goal arrived (NaN: none), the node's memory every 10 s, its last status."""
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped, TwistStamped
    from rclpy.node import Node

    from comanip.ros.messages import seconds, stamp_of, status_values
    from comanip.ros.replay import private_domain

    domain = private_domain()
    env = {**os.environ, "ROS_DOMAIN_ID": str(domain)}
    if src is not None:
        env["PYTHONPATH"] = str(src)
    command = [sys.executable, "-m", "comanip", "ros", "--preset", "arm", "--estimation-rate", str(rate)]
    if src is not None:   # a checkout without the command-line preset: the same settings from a file
        params = Path(os.environ.get("TMPDIR", "/tmp")) / f"node_at_tracker_rate_{os.getpid()}.yaml"
        params.write_text(f"preset: arm\nestimation_rate: {rate}\n")
        command = [sys.executable, "-m", "comanip", "ros", "--params", str(params)]
    node = subprocess.Popen(command, stderr=subprocess.DEVNULL, env=env)
    rclpy.init(domain_id=domain)
    player = Node("comanip_tracker")
    received, statuses = {}, []          # received: {a goal's stamp in integer nanoseconds: its wall time of arrival}
    player.create_subscription(PoseWithCovarianceStamped, "goal/estimate",
                               lambda m: received.setdefault(nanoseconds(m.header.stamp), time.time()), 1000)
    player.create_subscription(DiagnosticArray, "status", lambda m: statuses.append(status_values(m)), 50)
    pose_pub = player.create_publisher(PoseStamped, "hand/pose", 50)
    twist_pub = player.create_publisher(TwistStamped, "hand/twist", 50)
    sent, sent_ns = np.full(len(t), np.nan), [0] * len(t)
    memory = []
    try:
        started = time.time()
        while not statuses and time.time() - started < 120:
            rclpy.spin_once(player, timeout_sec=0.05)
        begin = time.time()
        next_memory = next_progress = 0.0
        for k, (tk, p) in enumerate(zip(t, position)):
            while (wait := begin + tk - time.time()) > 0:
                rclpy.spin_once(player, timeout_sec=wait)
            now = time.time()
            stamp = stamp_of(now)
            pose = PoseStamped()
            pose.header.stamp, pose.header.frame_id = stamp, "world"
            pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = (float(v) for v in p)
            pose.pose.orientation.w = 1.0
            if twists:
                twist = TwistStamped()
                twist.header.stamp, twist.header.frame_id = stamp, "world"
                velocity = (p - position[k - 1]) / (tk - t[k - 1]) if k else np.zeros(3)
                twist.twist.linear.x, twist.twist.linear.y, twist.twist.linear.z = (float(v) for v in velocity)
                twist_pub.publish(twist)
            pose_pub.publish(pose)
            sent[k], sent_ns[k] = seconds(stamp), nanoseconds(stamp)
            if tk >= next_memory:
                memory.append((tk, resident_mb(node.pid)))
                next_memory += 10.0
            if tk >= next_progress:
                print(f"  {label}: {tk / 60:.1f} of {t[-1] / 60:.1f} min, {len(received)} goals", file=sys.stderr, flush=True)
                next_progress += 60.0
        end = time.time() + 1.0
        while time.time() < end:
            rclpy.spin_once(player, timeout_sec=0.01)
        memory.append((t[-1], resident_mb(node.pid)))
    finally:
        node.terminate()
        node.wait(timeout=20)
        player.destroy_node()
        rclpy.try_shutdown()
    answered = np.array([received.get(ns, np.nan) for ns in sent_ns])
    return {"sent": sent, "answered": answered, "memory": memory, "status": statuses[-1] if statuses else {}}


def minute_rows(t, run: dict, reaches, rate: float) -> list[dict]:
    """Per minute of the run (module docstring), and the whole run as the last row."""
    latency = 1e3 * (run["answered"] - run["sent"])
    got = np.isfinite(latency)
    moving, found = np.zeros(len(t), dtype=bool), np.zeros(len(t), dtype=bool)
    for onset, end in reaches:
        within = (t >= onset) & (t <= end)
        moving |= within
        answered = np.flatnonzero(within & got)
        if answered.size:                    # from the reach's first goal on: found, and past the prior
            found |= within & (np.arange(len(t)) >= answered[0])
    stamps = run["sent"][got]
    first = np.zeros(len(t), dtype=bool)
    first[np.flatnonzero(got)] = np.r_[True, np.diff(stamps) > GAP]
    memory = np.array(run["memory"])
    rows = []
    spans = [(m * 60.0, (m + 1) * 60.0, f"{m}–{m + 1} min") for m in range(int(np.ceil(t[-1] / 60.0)))]
    for low, high, label in spans + [(0.0, np.inf, "all")]:
        part = (t >= low) & (t < high)
        values = latency[part & got & ~first]
        opening = latency[part & first]
        in_memory = memory[(memory[:, 0] < high)] if len(memory) else memory
        rows.append({
            "span": label, "poses": int(part.sum()), "moving": int((part & moving).sum()),
            "answered_moving": float(np.mean(got[part & moving])) if (part & moving).any() else np.nan,
            "answered_found": float(np.mean(got[part & found])) if (part & found).any() else np.nan,
            "in_period_found": float(np.mean(latency[part & found] <= 1e3 / rate)) if (part & found).any() else np.nan,
            "median_ms": float(np.median(values)) if values.size else np.nan,
            "p95_ms": float(np.percentile(values, 95)) if values.size else np.nan,
            "p99_ms": float(np.percentile(values, 99)) if values.size else np.nan,
            "max_ms": float(values.max()) if values.size else np.nan,
            "first_median_ms": float(np.median(opening)) if opening.size else np.nan,
            "first_p95_ms": float(np.percentile(opening, 95)) if opening.size else np.nan,
            "first_max_ms": float(opening.max()) if opening.size else np.nan,
            "memory_mb": float(in_memory[-1, 1]) if len(in_memory) else np.nan})
    return rows


def table(label: str, rows: list[dict]) -> list[str]:
    def cell(value, digits=2):
        return "–" if not np.isfinite(value) else f"{value:.{digits}f}"

    return [f"| {label} | {r['span']} | {r['poses']} | {100 * r['answered_moving']:.1f} % | {100 * r['answered_found']:.1f} % | "
            f"{100 * r['in_period_found']:.1f} % | "
            f"{cell(r['median_ms'])} / {cell(r['p95_ms'])} / {cell(r['p99_ms'])} / {cell(r['max_ms'], 1)} | "
            f"{cell(r['first_median_ms'])} / {cell(r['first_p95_ms'])} / {cell(r['first_max_ms'], 1)} | {cell(r['memory_mb'], 0)} |"
            for r in rows]


HEADER = ["| node | span | poses | poses of movements answered | from a reach's first goal on: answered | answered within "
          "the next pose's period | pose → goal, median / p95 / p99 / largest (ms) | first goal of a reach, median / p95 / "
          "largest (ms) | node memory (MB) |",
          "|---|---|---|---|---|---|---|---|---|"]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--rate", type=float, default=250.0, help="the tracker's poses per second and the node's "
                        "estimation_rate (Hz)")
    parser.add_argument("--twists", action="store_true", help="also publish a twist with each pose")
    parser.add_argument("--compare", help="another checkout (its folder) or a git revision whose node takes turns with "
                        "this one (both get twists)")
    parser.add_argument("--turn", type=float, default=2.0, help="minutes per turn with --compare")
    parser.add_argument("--markdown", action="store_true")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "node_at_tracker_rate")
    args = parser.parse_args(argv)
    if not ARMS.is_dir():
        sys.exit(f"no arm reaches at {ARMS}: this benchmark streams the recorded arm reaches of ../shared")
    load = os.getloadavg()[0]
    lines = list(HEADER)
    results = {}
    if args.compare is None:
        t, position, reaches = tracker_stream(args.minutes, args.rate)
        run = live_run(t, position, args.rate, args.twists, None, "this node")
        results["this node"] = minute_rows(t, run, reaches, args.rate)
        lines += table("this node" + (", poses and twists" if args.twists else ", poses only"), results["this node"])
    else:
        t, position, reaches = tracker_stream(args.turn, args.rate)
        reference, clean_up = reference_source(args.compare)
        runs = {"this node": [], f"previous ({args.compare})": []}
        try:
            for turn in range(max(1, int(round(args.minutes / args.turn)))):
                for label, src in zip(runs, (None, reference)):
                    runs[label].append(live_run(t, position, args.rate, True, src, f"{label}, turn {turn + 1}"))
        finally:
            clean_up()
        for label, turns in runs.items():
            rows = [minute_rows(t, run, reaches, args.rate)[-1] for run in turns]
            for k, row in enumerate(rows):
                row["span"] = f"turn {k + 1} ({args.turn:g} min)"
            results[label] = rows
            lines += table(f"{label}, poses and twists", rows)
    summary = "\n".join(lines)
    intro = (f"Measured by `benchmarks/node_at_tracker_rate.py --minutes {args.minutes:g} --rate {args.rate:g}"
             + (" --twists" if args.twists else "") + (f" --compare {args.compare} --turn {args.turn:g}" if args.compare else "")
             + f"` (the development arm reaches at {args.rate:g} Hz, the node in its own process; 1-minute load average "
             f"{load:.1f} on {os.cpu_count()} cores as the run began):\n\n")
    print(intro + summary if args.markdown else summary)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / ("compare.json" if args.compare else "run.json")).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
