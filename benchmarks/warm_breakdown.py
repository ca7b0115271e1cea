"""Where a warm point-mass solve spends its time: the per-iteration pieces of the Newton method, timed alone.

    .venv/bin/python benchmarks/warm_breakdown.py [planar cartesian ...]

For each preset, uncompiled and with ``SolverOptions(compile=True)``: the best of repeated timings (ms) of
one terms evaluation (f, its gradient and the per-step reward derivatives), one value-only evaluation (line
searches, ranking of initial guesses), one Hessian, one Cholesky factorisation, building the returned Plan,
and of a whole warm solve (goal moved within ±5 cm), with the mean iterations of such solves. BLAS is held
to one thread, as the planner does.
"""

from __future__ import annotations

import sys
import timeit

import numpy as np
import scipy.linalg
from threadpoolctl import threadpool_limits

import comanip
from comanip.planning.planner import SolverOptions


def best_ms(function, number: int = 20, repeat: int = 15) -> float:
    return 1e3 * min(timeit.repeat(function, number=number, repeat=repeat)) / number


def row(preset: str, compile: bool) -> str:
    model = comanip.presets.load(preset)
    planner = comanip.Planner(model, SolverOptions(compile=compile))
    start, goal, width = np.zeros(model.state_size), 0.3 * np.eye(model.d)[0], model.width
    plan = planner.solve(start, goal, width)
    x, params = plan.torque.ravel(), np.concatenate([start, goal, [width]])
    curvature = planner.curvature
    _, _, data = curvature.evaluate(x, params)
    hessian = curvature.hessian(data)
    rng = np.random.default_rng(0)

    def warm():
        return planner.solve(start, goal + rng.uniform(-0.05, 0.05, model.d), width, warm_start=plan)

    iterations = np.mean([warm().iterations for _ in range(10)])
    pieces = [best_ms(lambda: curvature.evaluate(x, params)), best_ms(lambda: curvature.value(x, params)),
              best_ms(lambda: curvature.hessian(data)), best_ms(lambda: scipy.linalg.cho_factor(hessian, check_finite=False)),
              best_ms(lambda: planner._make_plan(plan.torque, params, status="solved", success=True, message="",
                                                 solve_time=0.0, iterations=0)),
              best_ms(warm, number=5)]
    return f"| {preset}{', compiled' if compile else ''} | " + " | ".join(f"{p:.3f}" for p in pieces) + f" | {iterations:.1f} |"


def main(argv=None) -> None:
    presets = (argv if argv is not None else sys.argv[1:]) or ["planar", "cartesian"]
    print("| preset | terms evaluation | value only | Hessian | Cholesky | make_plan | warm solve | iterations |")
    print("|---|---|---|---|---|---|---|---|")
    with threadpool_limits(1, user_api="blas"):
        for preset in presets:
            for compile in (False, True):
                print(row(preset, compile), flush=True)


if __name__ == "__main__":
    main()
