"""Update times of goal estimation over an uninterrupted stream of successive reaches, from its first second to its last.

A hand in 3-D makes one reach after another (minimum-jerk, 0.15-0.35 m in random directions, 0.5 s each,
0.5 s at rest before each), sampled at ``--rate`` Hz with ``--noise`` m of position noise and velocities by a
backward difference over 24 ms, for ``--seconds`` s; :class:`comanip.ReachStream` (``--preset``) segments and
estimates it with no reset, in a process of its own. Printed: reaches in the stream and reaches found, and the
update time (median, p95, largest) per tenth of the stream, over all updates, over the updates while a reach is
under way and over each reach's first update (the one that sees the hand leave its rest, with the reach's lead).
``--compare REF`` streams the same samples a second time with the code of another checkout REF (a folder, or a git
revision checked out for the run), the two processes taking turns second by second, and prints both. Seeded: the
same stream every run.

    python benchmarks/reach_stream_times.py                    # 60 s at 250 Hz, the arm preset
    python benchmarks/reach_stream_times.py --seconds 20 --rate 125
    python benchmarks/reach_stream_times.py --compare main~1      # beside the code of another revision
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

import comanip

sys.path.insert(0, str(Path(__file__).resolve().parent))
from solve_times import reference_source, worker_reply  # noqa: E402  (beside this script)


def stream_of_reaches(seconds: float, rate: float, noise: float, seed: int = 0):
    """Times (K,) s, positions (K, 3) m, velocities (K, 3) m/s of the stream (module docstring), and its reach count."""
    rng = np.random.default_rng(seed)
    t, x, position, now, count = [], [], np.zeros(3), 0.0, 0
    while now < seconds - 1.0:
        for _ in range(int(0.5 * rate)):
            t.append(now), x.append(position.copy())
            now += 1 / rate
        direction = rng.normal(size=3)
        goal = position + rng.uniform(0.15, 0.35) * direction / np.linalg.norm(direction)
        if np.linalg.norm(goal) > 0.5:                           # stay within an arm's reach of the origin
            goal = 2 * position - goal
        for k in range(int(0.5 * rate)):
            s = k / (0.5 * rate)
            t.append(now), x.append(position + (goal - position) * (10 * s**3 - 15 * s**4 + 6 * s**5))
            now += 1 / rate
        position, count = goal, count + 1
    while now < seconds:
        t.append(now), x.append(position.copy())
        now += 1 / rate
    t, x = np.array(t), np.array(x) + rng.normal(0, noise, (len(t), 3))
    back = max(1, int(round(0.024 * rate)))
    return t, x, np.r_[np.zeros((back, 3)), (x[back:] - x[:-back]) / (back / rate)], count


def serve(seconds: float, rate: float, noise: float, preset: str) -> None:
    """Worker of one checkout: builds the stream and its :class:`comanip.ReachStream`, then for each line ``a b`` on
    stdin feeds samples a..b-1 and writes one JSON line: each sample's update time (ms), whether a reach was under
    way, and the reaches started so far."""
    t, x, v, count = stream_of_reaches(seconds, rate, noise)
    stream = comanip.ReachStream(comanip.presets.load(preset))
    print(json.dumps({"samples": len(t), "reaches": count}), flush=True)
    for line in sys.stdin:
        a, b = map(int, line.split())
        out = {"ms": [], "moving": [], "reach": []}
        for k in range(a, b):
            begin = time.perf_counter()
            latest = stream.update(t[k], x[k], v[k])
            out["ms"].append(1e3 * (time.perf_counter() - begin))
            out["moving"].append(latest.moving)
            out["reach"].append(latest.reach)
        print(json.dumps(out), flush=True)


def measure(srcs: list[Path], args) -> tuple[dict, list[dict]]:
    """The stream's size and, per checkout (``srcs``), every sample's update time, reach flag and reach count; each
    checkout in its own process, the processes taking turns second by second of the stream."""
    command = [sys.executable, __file__, "--serve", "--seconds", str(args.seconds), "--rate", str(args.rate),
               "--noise", str(args.noise), "--preset", args.preset]
    workers = [subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                env={**os.environ, "PYTHONPATH": str(src)}) for src in srcs]
    head = [worker_reply(worker) for worker in workers][0]
    runs = [{"ms": [], "moving": [], "reach": []} for _ in workers]
    chunk = max(1, int(args.rate))
    for a in range(0, head["samples"], chunk):
        for worker, run in zip(workers, runs):
            worker.stdin.write(f"{a} {min(a + chunk, head['samples'])}\n")
            worker.stdin.flush()
            for key, values in worker_reply(worker).items():
                run[key] += values
        print(f"  {a / args.rate:.0f} s", file=sys.stderr, end="\r", flush=True)
    for worker in workers:
        worker.stdin.close()
        worker.wait()
    return head, [{key: np.array(values) for key, values in run.items()} for run in runs]


def _stats(values: np.ndarray, largest: bool = True) -> str:
    if not len(values):
        return "–"
    parts = [np.median(values), np.percentile(values, 95)] + ([values.max()] if largest else [])
    return " / ".join(f"{v:.2f}" for v in parts)


def table(head: dict, runs: list[dict], names: list[str], args) -> str:
    """Per tenth of the stream and over all of it: every update, the updates while a reach is under way, and each
    reach's first update (the one that sees the hand leave its rest, with the reach's lead), per checkout."""
    t = np.arange(head["samples"]) / args.rate
    lines = [f"{args.seconds:g} s at {args.rate:g} Hz, {args.noise * 1e3:g} mm noise, `{args.preset}` preset: "
             f"{head['reaches']} reaches in the stream, " + ", ".join(f"{run['reach'][-1]} found ({name})" for run, name in
                                                                      zip(runs, names)), "",
             "| part of the stream | code | updates | median / p95 / largest (ms) | while a reach is under way: "
             "median / p95 (ms) | first update of a reach: median / p95 / largest (ms) |", "|---|---|---|---|---|---|"]
    edges = np.linspace(0.0, args.seconds, 11)
    parts = [(f"{low:.3g}–{high:.3g} s", (t >= low) & (t < high)) for low, high in zip(edges[:-1], edges[1:])]
    for label, part in parts + [("all", np.ones_like(t, dtype=bool))]:
        for run, name in zip(runs, names):
            first = part & (np.diff(run["reach"], prepend=0) > 0)
            lines.append(f"| {label} | {name} | {part.sum()} | {_stats(run['ms'][part])} | "
                         f"{_stats(run['ms'][part & run['moving']], largest=False)} | "
                         + _stats(run["ms"][first]) + " |")
    lines += ["", f"Measured by `benchmarks/reach_stream_times.py {' '.join(sys.argv[1:])}` (1-minute load average at "
              f"the end {os.getloadavg()[0]:.2f})."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=250.0, help="samples per second (Hz)")
    parser.add_argument("--noise", type=float, default=5e-4, help="position noise (m)")
    parser.add_argument("--preset", default="arm")
    parser.add_argument("--compare", default=None, help="another checkout (its folder) or a git revision to time beside this code")
    parser.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.serve:
        serve(args.seconds, args.rate, args.noise, args.preset)
        return
    here = Path(__file__).resolve().parents[1] / "src"
    if args.compare is None:
        print(table(*measure([here], args), ["this code"], args))
        return
    source, clean_up = reference_source(args.compare)
    try:
        head, runs = measure([here, source], args)
    finally:
        clean_up()
    print(table(head, runs, ["this code", f"previous ({args.compare})"], args))


if __name__ == "__main__":
    main()
