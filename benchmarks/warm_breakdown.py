"""Where a warm solve spends its time: the per-iteration pieces of the Newton method, timed alone.

    .venv/bin/python benchmarks/warm_breakdown.py [planar cartesian franka_rest ...] [--compare REF]

For each preset (the point masses uncompiled and with ``SolverOptions(compile=True)``, the Panda compiled,
as it always is): the best of repeated timings (ms) of one terms evaluation (f, its gradient and the per-step
pieces), one value-only evaluation (line searches, ranking of initial guesses), one Hessian (for the Panda
with the sensitivities d mu / d tau it starts from), one Cholesky factorisation, one secant (SR1) update
(approximate Hessians only) and building the returned Plan; then 15 warm solves (goal moved within ±5 cm per
axis, each from the same plan): the median ``solve_time``, the mean iterations and the best of each solve's time
over its iterations (solves of different lengths compare per iteration; the best, like the pieces, is the
least disturbed by other jobs on the machine). Start at the body's home
position, at rest; base goal 0.3 m along x for the point masses, [0.15, 0.1, -0.1] m from the ready pose for
the Panda (as in solve_times.py). BLAS is held to one thread, as the planner does.

``--compare REF``: every preset runs a second time, in its own process, with the code of the checkout REF
(e.g. a worktree at main), rows side by side, so both see the same machine load.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import timeit
from pathlib import Path

import numpy as np
import scipy.linalg
from threadpoolctl import threadpool_limits

import comanip
from comanip.planning.planner import SolverOptions
from comanip.planning.reach_parameters import ReachParameters

COLUMNS = ("terms evaluation", "value only", "Hessian", "Cholesky", "secant update", "make_plan", "warm solve",
           "iterations", "warm solve / iteration")


def best_ms(function, number: int = 20, repeat: int = 15) -> float:
    return 1e3 * min(timeit.repeat(function, number=number, repeat=repeat)) / number


def measure(preset: str, compile: bool) -> dict:
    """The row's timings (ms) and the mean iterations of a warm solve, keyed by COLUMNS."""
    from comanip.optim.hessian_models import symmetric_rank_one_update

    model = comanip.presets.load(preset)
    planner = comanip.Planner(model, SolverOptions(compile=compile))
    curvature = planner.curvature
    start = np.concatenate([model.body.home_position, np.zeros(model.n)])
    reach = (0.3, 0.0, 0.0) if model.body.is_linear else (0.15, 0.1, -0.1)
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + np.asarray(reach)[:model.d]
    plan = planner.solve(start, goal, model.width)
    x, params = plan.torque.ravel(), ReachParameters(start, goal, model.width)
    evaluated = curvature.evaluate(x, params)
    gradient, data = evaluated.gradient, evaluated.data

    def hessian():
        if curvature.carries_belief:
            data.sensitivities = None  # a new evaluation's Hessian starts from its sensitivities
        return curvature.hessian(data)

    matrix = hessian()
    rng = np.random.default_rng(0)

    def warm():
        return planner.solve(start, goal + rng.uniform(-0.05, 0.05, model.d), model.width, warm_start=plan)

    solves = [warm() for _ in range(15)]
    correction, step = np.zeros_like(matrix), rng.normal(scale=1e-3, size=x.size)
    times = {"terms evaluation": best_ms(lambda: curvature.evaluate(x, params)),
             "value only": best_ms(lambda: curvature.value(x, params)),
             "Hessian": best_ms(hessian),
             "Cholesky": best_ms(lambda: scipy.linalg.cho_factor(matrix, check_finite=False)),
             "secant update": (best_ms(lambda: symmetric_rank_one_update(correction, matrix, step, gradient))
                               if not curvature.exact else float("nan")),
             "make_plan": best_ms(lambda: planner.solver.make_plan(plan.torque, params, status="solved", success=True,
                                                             message="", solve_time=0.0, iterations=0)),
             "warm solve": 1e3 * float(np.median([s.solve_time for s in solves])),
             "iterations": float(np.mean([s.iterations for s in solves])),
             "warm solve / iteration": 1e3 * min(s.solve_time / s.iterations for s in solves)}
    return times


def variants(preset: str) -> list[bool]:
    """The compile settings a preset is timed with: both for point masses, compiled for an arm."""
    return [False, True] if comanip.presets.load(preset).body.is_linear else [True]


def text_row(preset: str, compile: bool, values: dict, label: str = "") -> str:
    name = f"{preset}{', compiled' if compile and comanip.presets.load(preset).body.is_linear else ''}{label}"
    cells = ["–" if np.isnan(values[c]) else (f"{values[c]:.1f}" if c == "iterations" else f"{values[c]:.3f}")
             for c in COLUMNS]
    return f"| {name} | " + " | ".join(cells) + " |"


def measured_elsewhere(src: Path, preset: str, compile: bool) -> dict:
    """measure(preset, compile) in a fresh process importing comanip from ``src``."""
    done = subprocess.run([sys.executable, __file__, preset, "--row", str(compile)],
                          env={**os.environ, "PYTHONPATH": str(src)}, check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("presets", nargs="*", default=["planar", "cartesian"])
    parser.add_argument("--compare", type=Path, default=None, help="another checkout to time side by side (its src/)")
    parser.add_argument("--row", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.row is not None:
        with threadpool_limits(1, user_api="blas"):
            print(json.dumps(measure(args.presets[0], args.row == "True")))
        return
    print("| preset | " + " | ".join(COLUMNS) + " |")
    print("|---" * (len(COLUMNS) + 1) + "|")
    here = Path(__file__).resolve().parents[1] / "src"
    for preset in args.presets:
        for compile in variants(preset):
            if args.compare is None:
                with threadpool_limits(1, user_api="blas"):
                    print(text_row(preset, compile, measure(preset, compile)), flush=True)
                continue
            for label, src in ((" (new)", here), (" (ref)", args.compare.resolve() / "src")):
                print(text_row(preset, compile, measured_elsewhere(src, preset, compile), label), flush=True)


if __name__ == "__main__":
    main()
