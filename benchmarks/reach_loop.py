"""Recorded arm reaches streamed back to back, with rests, through goal estimation with no reset: the robot's loop.

The development trials of a TAT-HUM folder (motion capture, ``../shared/data/arm_reaches/``) are joined into one
uninterrupted tracker stream: each trial from ``--rest`` s before its onset (its own recorded rest; a trial
recorded with less is held at its first position before that) to ``--after`` s past its end, moved so that it
starts where the previous one ended (the hand rests where it stopped, then reaches again in the recorded
direction). The stream is delivered as a live tracker would (:meth:`TrackedSamples.stream`: ``--rate`` Hz, raw
positions, backward-difference velocities, lost samples as NaN) to :class:`comanip.ReachStream` (``--preset``)
and, with ``--node``, replayed in lock step through the ROS 2 goal node (``ros`` extra; every pose estimated);
with ``--live S``, its first S seconds published in real time to the node running in its own process.

Printed, for each: the reaches in the stream, found (one start within ``MATCH_BEFORE`` s before the recorded
onset to half of its movement time; the goal node's first reach begins at the stream's first pose), missed and
split; the error / D of the goal estimate at 25/50/75/90 % of
each found reach's movement time (median [IQR] over reaches); the update time (ms) per tenth of the stream and
while a reach is under way. Outputs in ``--out``: ``reaches.csv`` (one row per reach) and ``summary.md``.

    python benchmarks/reach_loop.py                     # every development trial, the arm preset
    python benchmarks/reach_loop.py --limit 40 --node   # the first 40 trials, also through the node
    python benchmarks/reach_loop.py --node --live 60     # and live: the first 60 s to the node in its own process
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import comanip
from comanip.recordings import load_tathum
from comanip.recordings.motion_capture import TrackedSamples

ARMS = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
FRACTIONS = (0.25, 0.5, 0.75, 0.9)
MATCH_BEFORE = 0.3
"""A reach start found up to this long (s) before a recorded onset belongs to that reach."""
QUEUE_SPAN = 10.0
"""The live latencies are also given over the first and the last this many seconds (s) of the live run."""


@dataclass(frozen=True)
class RecordedReach:
    """One reach of the stream, on the stream's clock."""

    name: str
    onset: float
    """s."""
    end_time: float
    """s."""
    start: np.ndarray
    """Position at the onset (3,), m."""
    end: np.ndarray
    """Endpoint (3,), m."""

    @property
    def movement_time(self) -> float:
        return self.end_time - self.onset


def joined_stream(trials, rest: float, after: float) -> tuple[TrackedSamples, list[RecordedReach]]:
    """The trials joined into one tracked stream (module docstring), and its reaches."""
    times, positions, reaches = [], [], []
    clock, anchor = 0.0, None
    for trial in trials:
        recording = trial.recording()
        t = trial.t - trial.first_tracked
        keep = (t >= recording.onset - rest) & (t <= recording.end_time + after)
        t, position = t[keep], trial.position[keep]
        first = np.flatnonzero(np.all(np.isfinite(position), axis=1))[0]
        step = float(np.median(np.diff(t)))
        held = np.arange(recording.onset - rest, t[0] - 0.5 * step, step)          # rest the recording lacks
        t, position = np.r_[held, t], np.r_[np.repeat(position[first:first + 1], len(held), axis=0), position]
        shift = np.zeros(3) if anchor is None else anchor - position[first]
        begin = t[0]
        times.append(clock + t - begin)
        positions.append(position + shift)
        onset = clock + recording.onset - begin
        reaches.append(RecordedReach(trial.name, onset, clock + recording.end_time - begin,
                                     recording.position[np.searchsorted(recording.t, recording.onset)] + shift,
                                     recording.end + shift))
        anchor = recording.end + shift
        clock = times[-1][-1] + step
    return TrackedSamples("joined", np.concatenate(times), np.concatenate(positions), {}), reaches


def matched_starts(starts: list[float], reaches: list[RecordedReach]) -> list[list[int]]:
    """For each recorded reach, the indices of the found starts that belong to it (module docstring; the goal
    node begins its first reach at the stream's first pose, which belongs to the first recorded reach)."""
    return [[i for i, s in enumerate(starts)
             if (0.0 if j == 0 else r.onset - MATCH_BEFORE) <= s <= r.onset + 0.5 * r.movement_time]
            for j, r in enumerate(reaches)]


def scored(reaches, matches, t, goals, reach_numbers) -> list[dict]:
    """Per recorded reach: found / missed / split, and the error / D at FRACTIONS of the estimate of the reach
    found for it (the latest goal at or before each time while that reach was the one under way)."""
    rows = []
    for reach, found in zip(reaches, matches):
        row = {"reach": reach.name, "distance_m": float(np.linalg.norm(reach.end - reach.start)),
               "movement_time_s": reach.movement_time, "found": len(found)}
        for f in FRACTIONS:
            row[f"error_{f:g}"] = np.nan
            if len(found) != 1:
                continue
            seen = np.flatnonzero((t <= reach.onset + f * reach.movement_time) & (reach_numbers == found[0] + 1))
            if seen.size and np.all(np.isfinite(goals[seen[-1]])):
                row[f"error_{f:g}"] = float(np.linalg.norm(goals[seen[-1]] - reach.end)) / row["distance_m"]
        rows.append(row)
    return rows


def through_stream(preset: str, t, position, velocity):
    """ReachStream over the samples (the model's reach family built first, as at a robot's startup): its reach
    starts (s, each reach's clock zero), per sample the goal (3,), reach number, moving, and update time (ms)."""
    model = comanip.presets.load(preset)
    comanip.OnlineGoalEstimator(model, np.r_[position[0], np.zeros(model.state_size - model.n)])
    stream = comanip.ReachStream(model)
    K = len(t)
    goals, numbers, moving, times = np.full((K, 3), np.nan), np.zeros(K, dtype=int), np.zeros(K, dtype=bool), np.zeros(K)
    starts = []
    for k in range(K):
        begin = time.perf_counter()
        latest = stream.update(t[k], position[k], velocity[k])
        times[k] = 1e3 * (time.perf_counter() - begin)
        if latest.reach > len(starts):
            starts.append(latest.reach_start)
        numbers[k], moving[k] = latest.reach, latest.moving
        if latest.estimate is not None:
            goals[k] = latest.estimate.goal
    return starts, goals, numbers, moving, times


def published(statuses, goal_times, goals, t, clock_zero: float):
    """What a node published, on the stream's clock (``clock_zero``: the stamp of stream time 0): its reach starts
    (s) from its statuses' values, and per sample time ``t`` (K,) the latest goal published (K, 3; NaN before
    the first) and the reach it belongs to (K,), from goals (G, 3) stamped ``goal_times`` (G,) s, in order."""
    starts = sorted({float(v["reach_start_stamp_s"]) - clock_zero for v in statuses if int(v["reach"]) > 0})
    goal_t = np.asarray(goal_times) - clock_zero
    latest = np.searchsorted(goal_t, t + 1e-9, side="right") - 1
    goal = np.asarray(goals)
    at = goal[np.maximum(latest, 0)]
    return starts, np.where((latest >= 0)[:, None], at, np.nan), np.searchsorted(starts, goal_t[np.maximum(latest, 0)] + 1e-9,
                                                                               side="right")


def through_node(preset: str, rate: float, t, position, velocity):
    """The samples replayed through the goal node in lock step: its reach starts (s, each reach's clock zero),
    per sample the latest goal published (3,) and the reach it belongs to, the latencies (ms) the node's
    status reports and the wall time per pose (ms)."""
    from comanip.ros.node_settings import NodeSettings
    from comanip.ros.replay import BASE_STAMP, Replay

    tracked = np.all(np.isfinite(position), axis=1) & np.all(np.isfinite(velocity), axis=1)
    with Replay(NodeSettings(preset=preset, estimation_rate=2 * rate), None) as replay:
        recording = replay.run(t[tracked], np.c_[position, velocity][tracked])
    values = [v for *_, v in recording.statuses if int(v["reach"]) > 0]
    starts, goals, numbers = published(values, [stamp for stamp, *_ in recording.goals], [g for _, g, _, _ in recording.goals],
                                       t, BASE_STAMP)
    latency = 1e3 * np.array([float(v["last_latency_s"]) for v in values if v["last_latency_s"] not in (None, "")], dtype=float)
    latency = latency[np.isfinite(latency)]
    return starts, goals, numbers, latency, 1e3 * recording.wall_time / tracked.sum()


def live(preset: str, rate: float, seconds: float, t, position, velocity):
    """The first ``seconds`` of the stream published in real time to the goal node running in its own process
    (``python -m comanip ros``, estimating at ``rate`` Hz), as a robot's tracker would: its reach starts (s), per
    sample the latest goal received (3,) and the reach it belongs to, and what :func:`live_latency` reads from the
    run."""
    sys.path.insert(0, str(Path(__file__).parent))
    from ros_node_rate import two_processes

    keep = (t <= seconds) & np.all(np.isfinite(position), axis=1) & np.all(np.isfinite(velocity), axis=1)
    run = two_processes(rate, t[keep], np.c_[position, velocity][keep], goal=position[keep][-1],
                        parameters={"preset": preset, "estimator": "recorded"})
    stamps = sorted(run["goals"])
    starts, goals, numbers = published(run["statuses"], stamps, [run["goals"][s][1] for s in stamps], t, run["begin"])
    goals[t > seconds] = np.nan
    return starts, goals, numbers, live_latency(run, int(keep.sum()), [run["begin"] + s for s in starts])


def live_latency(run: dict, sent: int, starts: list[float]) -> dict:
    """From a live run (:func:`ros_node_rate.two_processes`): the latencies (ms) from publishing a pose to receiving
    the goal (``goal``) and the predicted path (``forecast``) made from it, the first estimate (a cold start) apart,
    each also over the first and the last ``QUEUE_SPAN`` s of the run (a queue that grows makes the last ones
    longer), and apart for the first estimate of each reach (``goal_first_of_reach``: the reach's lead replayed
    first; ``starts``, the reaches' clocks, s) and for the others (``goal_within_reach``); the estimate's own time
    (``solve``, ms, as the node's status reports it after each estimate); the poses sent, those the node never
    received (``dropped``), and those it did not estimate (``skipped``: between due times, or replaced by a newer
    one while an estimate ran); the machine's load average as the run began (``load``)."""
    every = sorted(run["goals"])
    reach_of = np.searchsorted(starts, every, side="right")
    opening = np.r_[True, reach_of[1:] != reach_of[:-1]][1:]
    stamps = every[1:]
    paths = {round(stamp, 5): received for stamp, received in run["paths"].items()}
    goal = 1e3 * np.array([run["goals"][s][0] - s for s in stamps])
    forecast = 1e3 * np.array([paths.get(round(s, 5), np.nan) - s for s in stamps])
    since = np.array(stamps) - run["begin"]
    first, last = since <= since[0] + QUEUE_SPAN, since >= since[-1] - QUEUE_SPAN
    status = run["statuses"][-1]
    solve = {}
    for values in run["statuses"]:
        if values["estimate_stamp_s"] not in ("", "nan", None):
            solve.setdefault(values["estimate_stamp_s"], 1e3 * float(values["last_solve_time_s"]))
    return {"goal": goal, "forecast": forecast[np.isfinite(forecast)], "goal_first": goal[first], "goal_last": goal[last],
            "goal_first_of_reach": goal[opening], "goal_within_reach": goal[~opening], "solve": np.array(list(solve.values())),
            "estimates": len(every), "sent": sent, "dropped": sent - int(status["inputs"]), "skipped": int(status["skipped"]),
            "load": run["load"]}


def live_summary(latency: dict, tracker_rate: float, estimation_rate: float) -> str:
    """The live run's latencies and queue (:func:`live_latency`) as a paragraph."""
    def spread(values):
        return f"median {np.median(values):.1f} ms, p95 {np.percentile(values, 95):.1f} ms"

    return (f"Live, the node in its own process fed in real time by a {tracker_rate:g} Hz tracker, estimating at "
            f"{estimation_rate:g} Hz: latency from publishing a pose to receiving its goal {spread(latency['goal'])}, its "
            f"forecast (the predicted path) {spread(latency['forecast'])} ({latency['estimates']} estimates of "
            f"{latency['sent']} poses; {latency['skipped']} skipped, {latency['dropped']} dropped); the estimate itself, as "
            f"the node's status reports it, {spread(latency['solve'])}; the first goal of each reach, whose lead the "
            f"estimator gets first, {spread(latency['goal_first_of_reach'])}, the others {spread(latency['goal_within_reach'])}"
            f" (load average {latency['load']:.2f} as the run began). The queue: goal latency "
            f"over the first {QUEUE_SPAN:g} s {spread(latency['goal_first'])}, over the last {QUEUE_SPAN:g} s "
            f"{spread(latency['goal_last'])}.")


def error_table(label: str, rows) -> str:
    cells = []
    for f in FRACTIONS:
        errors = np.array([row[f"error_{f:g}"] for row in rows], dtype=float)
        errors = errors[np.isfinite(errors)]
        cells.append(f"{np.median(errors):.3f} [{np.percentile(errors, 25):.2f}–{np.percentile(errors, 75):.2f}]"
                     if errors.size else "–")
    found = [row["found"] for row in rows]
    return (f"| {label} | {len(rows)} | {found.count(1)} | {found.count(0)} | {sum(1 for n in found if n > 1)} | "
            + " | ".join(cells) + " |")


def time_table(t, times, moving) -> str:
    lines = ["| part of the stream | updates | median / p95 / largest (ms) | while a reach is under way: median / p95 (ms) |",
             "|---|---|---|---|"]
    edges = np.linspace(t[0], t[-1] + 1e-9, 11)
    parts = [(f"{low:.0f}–{high:.0f} s", (t >= low) & (t < high)) for low, high in zip(edges[:-1], edges[1:])]
    for label, part in parts + [("all", np.ones(len(t), dtype=bool))]:
        reach = part & moving
        during = f"{np.median(times[reach]):.2f} / {np.percentile(times[reach], 95):.2f}" if reach.any() else "–"
        lines.append(f"| {label} | {part.sum()} | {np.median(times[part]):.2f} / {np.percentile(times[part], 95):.2f} / "
                     f"{times[part].max():.1f} | {during} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--arms", type=Path, default=ARMS, help="a TAT-HUM 3-D data folder (trajectory_data/, trial_data/)")
    parser.add_argument("--limit", type=int, default=None, help="at most this many trials")
    parser.add_argument("--rest", type=float, default=0.5, help="rest before each reach's onset (s)")
    parser.add_argument("--after", type=float, default=0.2, help="time kept after each reach's end (s)")
    parser.add_argument("--rate", type=float, default=125.0, help="tracker samples per second (Hz)")
    parser.add_argument("--preset", default="arm")
    parser.add_argument("--node", action="store_true", help="also replay the stream through the ROS 2 goal node")
    parser.add_argument("--live", type=float, default=0.0, help="also publish the first LIVE s of the stream in real time "
                        "to the goal node in its own process (0: not)")
    parser.add_argument("--live-rate", type=float, default=50.0, help="the live node's estimation_rate (Hz)")
    parser.add_argument("--live-tracker-rate", type=float, default=None, help="tracker samples per second of the live "
                        "stream (Hz; default: --rate)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "reach_loop")
    args = parser.parse_args(argv)
    if not args.arms.is_dir():
        sys.exit(f"no arm reaches at {args.arms}: pass --arms FOLDER (a TAT-HUM data_3d folder)")
    trials = load_tathum(args.arms)[:args.limit]
    tracked, reaches = joined_stream(trials, args.rest, args.after)
    t, position, velocity = tracked.stream(rate_hz=args.rate)
    print(f"{len(reaches)} recorded arm reaches joined into one {t[-1]:.0f} s stream at {args.rate:g} Hz", file=sys.stderr)
    starts, goals, numbers, moving, times = through_stream(args.preset, t, position, velocity)
    rows = scored(reaches, matched_starts(starts, reaches), t, goals, numbers)
    header = ("| through | reaches | found | missed | split | " + " | ".join(f"error / D at {100 * f:g} % of MT" for f in FRACTIONS)
              + " |\n|---|---|---|---|---|" + "---|" * len(FRACTIONS))
    lines = [error_table("ReachStream", rows)]
    node_line = ""
    if args.node:
        node_starts, node_goals, node_numbers, latency, per_pose = through_node(args.preset, args.rate, t, position, velocity)
        node_rows = scored(reaches, matched_starts(node_starts, reaches), t, node_goals, node_numbers)
        lines.append(error_table("goal node (replay, lock step)", node_rows))
        node_line = (f"\n\nThe goal node: latency from a pose's arrival to its goal's publication (as its status reports "
                     f"it) median {np.median(latency):.2f} ms, p95 {np.percentile(latency, 95):.2f} ms; "
                     f"{per_pose:.2f} ms of wall time per pose in lock step.")
        for row, node_row in zip(rows, node_rows):
            row.update({f"node_{k}": v for k, v in node_row.items() if k.startswith(("found", "error"))})
    if args.live > 0:
        tracker_rate = args.live_tracker_rate or args.rate
        live_t, live_position, live_velocity = (t, position, velocity) if tracker_rate == args.rate else \
            tracked.stream(rate_hz=tracker_rate)
        live_starts, live_goals, live_numbers, latency = live(args.preset, args.live_rate, args.live, live_t, live_position,
                                                              live_velocity)
        within = [k for k, r in enumerate(reaches) if r.end_time <= args.live]
        live_rows = scored([reaches[k] for k in within], matched_starts(live_starts, [reaches[k] for k in within]), live_t,
                           live_goals, live_numbers)
        lines.append(error_table(f"goal node, live: its own process, real time, {tracker_rate:g} Hz tracker, "
                                 f"{args.live_rate:g} Hz estimation_rate, first {args.live:g} s", live_rows))
        node_line += "\n\n" + live_summary(latency, tracker_rate, args.live_rate)
    summary = (f"{len(reaches)} recorded arm reaches ({args.arms.name}, development split) back to back with "
               f"{args.rest:g} s of rest, one {t[-1]:.0f} s stream at {args.rate:g} Hz, `{args.preset}` preset, no reset: "
               f"reaches found, and error / D, median [IQR] over the found reaches\n\n{header}\n" + "\n".join(lines)
               + node_line + "\n\nReachStream update times over the stream:\n\n" + time_table(t, times, moving))
    print(summary)
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "reaches.csv", "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    (args.out / "summary.md").write_text(summary + "\n")


if __name__ == "__main__":
    main()
