"""Update times of goal estimation over an uninterrupted stream of successive reaches, from its first second to its last.

A hand in 3-D makes one reach after another (minimum-jerk, 0.15-0.35 m in random directions, 0.5 s each,
0.5 s at rest before each), sampled at ``--rate`` Hz with ``--noise`` m of position noise and velocities by a
backward difference over 24 ms, for ``--seconds`` s; :class:`comanip.ReachStream` (``--preset``) segments and
estimates it with no reset. Printed: reaches in the stream and reaches found, and the update time (median,
p95, largest) per tenth of the stream, over all updates and over the updates while a reach is under way.
Seeded: the same stream every run.

    python benchmarks/reach_stream_times.py                    # 60 s at 250 Hz, the arm preset
    python benchmarks/reach_stream_times.py --seconds 20 --rate 125
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import comanip


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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=250.0, help="samples per second (Hz)")
    parser.add_argument("--noise", type=float, default=5e-4, help="position noise (m)")
    parser.add_argument("--preset", default="arm")
    args = parser.parse_args(argv)
    t, x, v, count = stream_of_reaches(args.seconds, args.rate, args.noise)
    stream = comanip.ReachStream(comanip.presets.load(args.preset))
    times, moving = np.zeros(len(t)), np.zeros(len(t), dtype=bool)
    for k in range(len(t)):
        begin = time.perf_counter()
        latest = stream.update(t[k], x[k], v[k])
        times[k] = 1e3 * (time.perf_counter() - begin)
        moving[k] = latest.moving
    print(f"{args.seconds:g} s at {args.rate:g} Hz, {args.noise * 1e3:g} mm noise, `{args.preset}` preset: "
          f"{count} reaches in the stream, {latest.reach} found\n")
    print("| part of the stream | updates | median / p95 / largest (ms) | while a reach is under way: median / p95 (ms) |")
    print("|---|---|---|---|")
    edges = np.linspace(0.0, args.seconds, 11)
    for low, high in zip(edges[:-1], edges[1:]):
        part = (t >= low) & (t < high)
        reach = part & moving
        print(f"| {low:.0f}–{high:.0f} s | {part.sum()} | {np.median(times[part]):.2f} / {np.percentile(times[part], 95):.2f} / "
              f"{times[part].max():.1f} | {np.median(times[reach]):.2f} / {np.percentile(times[reach], 95):.2f} |")
    print(f"| all | {len(t)} | {np.median(times):.2f} / {np.percentile(times, 95):.2f} / {times.max():.1f} | "
          f"{np.median(times[moving]):.2f} / {np.percentile(times[moving], 95):.2f} |")


if __name__ == "__main__":
    main()
