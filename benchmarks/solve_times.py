"""Solve-time benchmark: median and p90 wall time of repeated solves, one row per case.

    .venv/bin/python benchmarks/solve_times.py [--repeats 50] [--only planar,cartesian]

Each case builds its solver once (build time reported apart), runs one cold solve, then times `repeats`
warm solves with varied goals. Add a case by adding to CASES a key (used by --only) and a function that
returns a Case.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

import comanip


@dataclass
class Case:
    """One benchmark row: ``solve(k)`` runs the k-th timed solve and returns (seconds, success)."""

    name: str
    build_time: float
    solve: Callable[[int], tuple[float, bool]]
    paper_time: float | None = None


def point_mass_case(preset: str, paper_time: float) -> Callable[[], Case]:
    def make() -> Case:
        model = comanip.presets.load(preset)
        t0 = time.perf_counter()
        planner = comanip.Planner(model)
        build = time.perf_counter() - t0
        rng = np.random.default_rng(0)
        start = np.zeros(2 * model.n)
        base = np.zeros(model.d)
        base[0] = 0.3
        previous = planner.solve(start, base, model.width)

        def solve(k: int) -> tuple[float, bool]:
            nonlocal previous
            goal = base + rng.uniform(-0.05, 0.05, model.d)
            plan = planner.solve(start, goal, model.width, warm_start=previous)
            previous = plan
            return plan.solve_time, plan.success

        return Case(f"{preset} warm (H={model.H}, n={model.n})", build, solve, paper_time)

    return make


def closed_loop_reach_case() -> Case:
    """One closed-loop reach of the transition-data person (planar, 2H = 60 replans, D = 0.3 m, w = 0.02 m):
    the unit of `comanip transition generate` (conditions × trials reaches, spread over the workers)."""
    from comanip.execution import execute_receding_horizon

    model = comanip.presets.planar()
    t0 = time.perf_counter()
    planner = comanip.Planner(model)
    build = time.perf_counter() - t0
    rng = np.random.default_rng(0)

    def solve(k: int) -> tuple[float, bool]:
        t = time.perf_counter()
        run = execute_receding_horizon(planner, np.zeros(4), [0.3, 0.0], 0.02, steps=2 * model.H, rng=rng)
        return time.perf_counter() - t, run.failed_replans == 0

    return Case(f"planar closed-loop reach ({2 * model.H} replans)", build, solve)


CASES: dict[str, Callable[[], Case]] = {
    "planar": point_mass_case("planar", 0.04),
    "cartesian": point_mass_case("cartesian", 0.20),
    "closed_loop": closed_loop_reach_case,
}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=50)
    parser.add_argument("--only", default="", help=f"comma-separated case keys to run, of: {', '.join(CASES)}")
    args = parser.parse_args(argv)
    wanted = [w for w in args.only.split(",") if w]
    print(f"{'case':<42} {'build s':>8} {'median ms':>10} {'p90 ms':>8} {'ok':>6} {'paper ms':>9} {'speed-up':>9}")
    for key, make in CASES.items():
        if wanted and key not in wanted:
            continue
        case = make()
        runs = [case.solve(k) for k in range(args.repeats)]
        times = np.array([t for t, _ in runs])
        ok = sum(s for _, s in runs)
        median, p90 = np.median(times), np.percentile(times, 90)
        paper = f"{1e3 * case.paper_time:9.0f}" if case.paper_time else f"{'-':>9}"
        speedup = f"{case.paper_time / median:8.1f}x" if case.paper_time else f"{'-':>9}"
        print(f"{case.name:<42} {case.build_time:8.2f} {1e3 * median:10.2f} {1e3 * p90:8.2f} {ok:>3}/{len(runs):<2} {paper} {speedup}", flush=True)


if __name__ == "__main__":
    main()
