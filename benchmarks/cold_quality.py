"""Cold-solve quality: random cold problems per preset, the current planner against a reference.

    .venv/bin/python benchmarks/cold_quality.py [--problems 200] [--presets planar,cartesian,human,human_cartesian]
                                                [--compare /path/to/worktree-at-main]
    .venv/bin/python benchmarks/cold_quality.py --presets franka_rest,franka   # the Panda: minutes per problem set
    .venv/bin/python benchmarks/cold_quality.py --workspace [--presets planar]   # the sampled workspace sets
    .venv/bin/python benchmarks/cold_quality.py --presets franka_rest --away     # arms from poses off the ready pose

Problems (the same for both sides, seeded): point masses: goals 0.1–0.4 m from the start in uniformly drawn
directions, widths log-uniform over 5–50 mm, every other start in motion (velocities uniform in ±0.3 m/s per
axis); arms: from the ready pose, goals 0.15–0.3 m from its hand, widths log-uniform over 2.5–10 cm, every
tenth start in motion (±0.3 rad/s per joint; the reach library's plans then start with braking moves
superposed); ``--away``: from joint positions within ±0.3 rad of the ready pose, where no reach library serves
and an arm's cold search runs its minimum-jerk guesses. ``--workspace``: the problems of each preset's sampled workspace set instead (benchmarks/workspace.py:
point masses' goals 0.05–0.8 m away, starts moving at up to 1 m/s; arms' goals 0.1–0.3 m away; widths 5–50 mm).
The reference is the code of another checkout (``--compare``: its src/ is imported in a separate process)
or, without it, this code with ``SolverOptions(cold_search="all")`` (every minimum-jerk guess solved to
convergence, the best kept). Each side runs in its own process, the presets alternating between them.

Prints per preset and kind of start (rest, moving, all): objectives of the current code worse / better /
equal (relative 1e-6) than the reference, successes, median and p90 solve times, median iterations, and whether
the cold-search rule is met (:data:`RULE_CLOSE`, :data:`RULE_SHARE`, :data:`RULE_WORST`); writes
every problem's row to benchmarks/results/cold_quality.csv (``--summarise CSV`` prints a CSV's table again).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

PRESETS = ("planar", "cartesian", "human", "human_cartesian")
RELATIVE = 1e-6
"""Objectives within this relative difference count as equal."""
RULE_CLOSE, RULE_SHARE, RULE_WORST = 1e-4, 0.98, 1e-3
"""The cold-search rule: a cold result within RULE_CLOSE relative of the reference's (the full search) in at
least RULE_SHARE of the problems, never more than RULE_WORST worse, and no fewer successes."""


def problems(model, count: int, seed: int = 0) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """(start (2n,), goal (d,), width) for ``count`` random cold problems of a model (module docstring)."""
    if not model.body.is_linear:
        return arm_problems(model, count, seed)
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        start = np.zeros(2 * model.n)
        if k % 2:
            start[model.n:] = rng.uniform(-0.3, 0.3, model.n)
        direction = rng.normal(size=model.d)
        goal = rng.uniform(0.1, 0.4) * direction / np.linalg.norm(direction)
        width = float(np.exp(rng.uniform(np.log(0.005), np.log(0.05))))
        out.append((start, goal, width))
    return out


AWAY = 0.3
"""Largest offset (rad) of each joint from the ready pose in ``--away`` problems."""


def arm_problems(model, count: int, seed: int = 0, away: bool = False) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """An arm's cold problems: from its ready pose (``away``: from joint positions drawn uniformly within ±AWAY rad of
    it, clipped to the limits, where no reach library serves), at rest except every tenth start (joint velocities
    uniform in ±0.3 rad/s), to goals 0.15–0.3 m from its hand in uniform directions, widths log-uniform over
    2.5–10 cm."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        pose = model.body.clip_to_limits(model.body.home_position + rng.uniform(-AWAY, AWAY, model.n)) if away \
            else model.body.home_position
        hand = np.asarray(model.body.kinematics_function(pose)[0]).ravel()
        start = np.r_[pose, np.zeros(model.n)]
        if k % 10 == 9:
            start[model.n:] = rng.uniform(-0.3, 0.3, model.n)
        direction = rng.normal(size=model.d)
        goal = hand + rng.uniform(0.15, 0.3) * direction / np.linalg.norm(direction)
        width = float(np.exp(rng.uniform(np.log(0.025), np.log(0.1))))
        out.append((start, goal, width))
    return out


def workspace_problems(preset: str, count: int) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """(start, goal, width) of the first ``count`` problems of the preset's sampled workspace set."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import workspace

    return [(p.start, p.goal, p.width) for p in workspace.load(preset)[:count]]


def worker(preset: str, count: int, cold_search: str | None, seed: int = 0, sampled: bool = False, away: bool = False) -> None:
    """Solve the preset's problems (``sampled``: its workspace set's; ``away``: an arm's from poses away from the ready
    pose) with the comanip on sys.path; one JSON line per problem on stdout."""
    import comanip
    from comanip.planning.planner import SolverOptions

    model = comanip.presets.load(preset)
    options = SolverOptions(cold_search=cold_search) if cold_search else SolverOptions()
    planner = comanip.Planner(model, options)
    rest = np.r_[model.body.home_position, np.zeros(model.n)]
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    planner.solve(rest, hand + 0.2 * np.eye(model.d)[0], model.width)  # one-off work, untimed
    chosen = workspace_problems(preset, count) if sampled else \
        arm_problems(model, count, seed, away) if away else problems(model, count, seed)
    for start, goal, width in chosen:
        plan = planner.solve(start, goal, width)
        hand = np.asarray(model.body.kinematics_function(start[: model.n])[0]).ravel()
        print(json.dumps({"objective": plan.objective, "success": plan.success, "time": plan.solve_time,
                          "iterations": plan.iterations, "distance_over_width": float(np.linalg.norm(goal - hand) / width),
                          "moving": bool(np.any(start[model.n:]))}), flush=True)


def run_side(src: Path, cold_search: str | None, preset: str, count: int, seed: int = 0, sampled: bool = False,
             away: bool = False) -> list[dict]:
    """The worker's rows for one preset, run in a fresh process importing comanip from ``src``."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    command = [sys.executable, __file__, "--worker", preset, "--problems", str(count), "--seed", str(seed)]
    if cold_search:
        command += ["--cold-search", cold_search]
    if sampled:
        command += ["--workspace"]
    if away:
        command += ["--away"]
    done = subprocess.run(command, env=env, check=True, capture_output=True, text=True)
    return [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]


HEADER = (f"{'preset':<16} {'start':<7} {'worse':>6} {'better':>7} {'equal':>6} {'ok new':>7} {'ok ref':>7} "
          f"{'new ms':>8} {'ref ms':>8} {'new p90':>8} {'ref p90':>8} {'new it':>7} {'ref it':>7} {'new it90':>8} {'ref it90':>8}")


def summary(rows: list[dict]) -> list[str]:
    """Table lines: per preset and start (rest, moving, all), the verdict counts, successes, median and p90
    times and median and p90 iterations of both sides."""
    lines = [HEADER]
    for preset in dict.fromkeys(row["preset"] for row in rows):
        for start, keep in (("rest", False), ("moving", True), ("all", None)):
            part = [r for r in rows if r["preset"] == preset and (keep is None or r["moving"] == keep)]
            counts = {v: sum(r["verdict"] == v for r in part) for v in ("worse", "better", "equal")}
            t_new, t_ref = (np.array([float(r[key]) for r in part]) for key in ("new_ms", "ref_ms"))
            it_new, it_ref = (np.median([int(r[key]) for r in part]) for key in ("new_iterations", "ref_iterations"))
            it90_new, it90_ref = (np.percentile([int(r[key]) for r in part], 90) for key in ("new_iterations", "ref_iterations"))
            ok_new, ok_ref = (sum(r[key] for r in part) for key in ("new_success", "ref_success"))
            lines.append(f"{preset:<16} {start:<7} {counts['worse']:>6} {counts['better']:>7} {counts['equal']:>6} {ok_new:>7} {ok_ref:>7} "
                         f"{np.median(t_new):8.2f} {np.median(t_ref):8.2f} {np.percentile(t_new, 90):8.2f} "
                         f"{np.percentile(t_ref, 90):8.2f} {it_new:7.0f} {it_ref:7.0f} {it90_new:8.0f} {it90_ref:8.0f}")
    return lines


def rule_verdicts(rows: list[dict]) -> list[str]:
    """Per preset, the cold-search rule (:data:`RULE_CLOSE`, :data:`RULE_SHARE`, :data:`RULE_WORST`) against the
    reference: the share within RULE_CLOSE, the largest relative excess, the successes, and whether it is met."""
    lines = [f"rule: within {RULE_CLOSE:g} relative in ≥ {RULE_SHARE:.0%}, never more than {RULE_WORST:g} worse, "
             "successes not fewer"]
    for preset in dict.fromkeys(row["preset"] for row in rows):
        part = [r for r in rows if r["preset"] == preset]
        relative = np.array([float(r["relative"]) for r in part])
        close, worst = float(np.mean(relative <= RULE_CLOSE)), float(relative.max())
        ok_new, ok_ref = (sum(r[key] for r in part) for key in ("new_success", "ref_success"))
        met = close >= RULE_SHARE and worst <= RULE_WORST and ok_new >= ok_ref
        lines.append(f"{preset:<16} within {RULE_CLOSE:g}: {close:.1%} ({len(part)} problems), largest excess {worst:.2e}, "
                     f"successes {ok_new}/{ok_ref}: {'met' if met else 'NOT met'}")
    return lines


def read_rows(path: Path) -> list[dict]:
    """The rows of a CSV this script wrote, typed back."""
    with open(path) as file:
        rows = list(csv.DictReader(file))
    for row in rows:
        for key in ("moving", "new_success", "ref_success"):
            row[key] = row[key] == "True"
    return rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--problems", type=int, default=200)
    parser.add_argument("--presets", default=",".join(PRESETS))
    parser.add_argument("--seed", type=int, default=0, help="seed of the random problems (default: %(default)s)")
    parser.add_argument("--compare", type=Path, default=None, help="checkout of the reference code (its src/ is used)")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "results" / "cold_quality.csv",
                        help="the CSV of every problem's row (default: %(default)s)")
    parser.add_argument("--summarise", type=Path, default=None, help="print the table of a CSV written before, solve nothing")
    parser.add_argument("--workspace", action="store_true", help="the sampled workspace sets' problems (benchmarks/workspace.py)")
    parser.add_argument("--away", action="store_true", help=f"arms: start from poses within ±{AWAY} rad of the ready pose per joint")
    parser.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--cold-search", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.worker, args.problems, args.cold_search, args.seed, args.workspace, args.away)
        return
    if args.summarise:
        rows = read_rows(args.summarise)
        print("\n".join(summary(rows) + rule_verdicts(rows)))
        return
    here = Path(__file__).resolve().parents[1] / "src"
    reference = (args.compare.resolve() / "src", None) if args.compare else (here, "all")
    label = f"{args.compare}" if args.compare else "cold_search='all'"
    print(f"reference: {label}; {args.problems} problems per preset; equal = within {RELATIVE:g} relative", flush=True)
    rows = []
    for preset in args.presets.split(","):
        new = run_side(here, None, preset, args.problems, args.seed, args.workspace, args.away)
        ref = run_side(*reference, preset, args.problems, args.seed, args.workspace, args.away)
        for k, (a, b) in enumerate(zip(new, ref)):
            relative = (a["objective"] - b["objective"]) / abs(b["objective"])
            verdict = "worse" if relative > RELATIVE else "better" if relative < -RELATIVE else "equal"
            rows.append({"preset": preset, "problem": k, "distance_over_width": a["distance_over_width"],
                         "moving": a["moving"], "new_objective": a["objective"], "ref_objective": b["objective"],
                         "relative": relative, "verdict": verdict, "new_success": a["success"], "ref_success": b["success"],
                         "new_ms": 1e3 * a["time"], "ref_ms": 1e3 * b["time"], "new_iterations": a["iterations"],
                         "ref_iterations": b["iterations"]})
            if verdict == "worse":
                print(f"  {preset} worse: problem {k}, D/w {a['distance_over_width']:.1f}, moving {a['moving']}, "
                      f"relative {relative:.2e}", flush=True)
    print("\n".join(summary(rows) + rule_verdicts(rows)))
    write_rows(args.out, rows)


def write_rows(path: Path, rows: list[dict]) -> None:
    """Every problem's row (dicts with the same keys) to a CSV at ``path`` (its folder made if missing)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as file:
        writer = csv.DictWriter(file, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
