"""Per-solve time of a loop of solves in one process: cold, chained warm (each from the previous plan) and warm
from one plan (every solve from the first plan), the best of three passes.

    PYTHONPATH=src .venv/bin/python benchmarks/solve_loop.py [--preset human] [--solves 300]
    PYTHONPATH=/path/to/other/checkout/src .venv/bin/python benchmarks/solve_loop.py    # the same for other code

Goals: cold, 0.1–0.4 m from rest in uniformly drawn directions; warm, within ±5 cm per axis of 0.3 m along x.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import comanip
from comanip.planning.planner import SolverOptions


def best_of_three(solve_all) -> float:
    """The fastest of three passes of ``solve_all`` (returns the number of solves), ms per solve."""
    times = []
    for _ in range(3):
        begin = time.perf_counter()
        count = solve_all()
        times.append((time.perf_counter() - begin) / count * 1e3)
    return min(times)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--preset", default="human")
    parser.add_argument("--solves", type=int, default=300)
    args = parser.parse_args(argv)
    model = comanip.presets.load(args.preset)
    planner = comanip.Planner(model, SolverOptions(compile=True))
    rng = np.random.default_rng(0)
    start = np.zeros(model.state_size)
    directions = rng.normal(size=(args.solves, model.d))
    cold = rng.uniform(0.1, 0.4, (args.solves, 1)) * directions / np.linalg.norm(directions, axis=1, keepdims=True)
    near = 0.3 * np.eye(model.d)[0] + rng.uniform(-0.05, 0.05, (args.solves, model.d))
    first = planner.solve(start, near[0], model.width)
    for goal in cold[:20]:                    # compiled functions loaded, libraries filled: untimed
        planner.solve(start, goal, model.width)

    def cold_solves():
        for goal in cold:
            planner.solve(start, goal, model.width)
        return len(cold)

    def chained_warm_solves():
        plan = first
        for goal in near:
            plan = planner.solve(start, goal, model.width, warm_start=plan)
        return len(near)

    def warm_solves_from_one_plan():
        for goal in near:
            planner.solve(start, goal, model.width, warm_start=first)
        return len(near)

    print(f"{args.preset}, {args.solves} solves, best of three passes (ms per solve, {comanip.__file__})")
    for name, solve_all in (("cold", cold_solves), ("warm, chained", chained_warm_solves),
                            ("warm, all from one plan", warm_solves_from_one_plan)):
        print(f"  {name:<26} {best_of_three(solve_all):.3f}")


if __name__ == "__main__":
    main()
