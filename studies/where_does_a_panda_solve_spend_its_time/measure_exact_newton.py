"""How many Newton iterations would a Panda solve take with the exact Hessian instead of the planner's approximation?

    PYTHONPATH=src .venv/bin/python -m studies.where_does_a_panda_solve_spend_its_time.measure_exact_newton [--problems 3] [--cold]

On the first problems of the ``franka_rest`` workspace set (benchmarks/workspace.py, starts at rest): the planner's
start for the warm solve (the plan to the problem's goal, then its start for the warm goal) or, with ``--cold``, for
the cold solve; from it, the planner's Newton method with its approximate Hessian and secant corrections, and the
same method (same tolerance, joint limits, line search) with the exact Hessian of the same objective, CasADi's
Jacobian of the gradient, evaluated in CasADi's virtual machine (seconds per Hessian: only for counting iterations).
Prints per problem both iteration counts, objectives and statuses, and the time of one exact Hessian.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--problems", type=int, default=3)
    parser.add_argument("--cold", action="store_true", help="the cold solves' starts instead of the warm ones'")
    args = parser.parse_args(argv)
    import comanip
    from benchmarks import workspace
    from comanip.optim.active_set_newton import newton_minimize
    from comanip.planning.path_limits import LIMIT_TOLERANCE
    from comanip.planning.planner import SolverOptions
    from comanip.planning.reach_parameters import ReachParameters

    model = comanip.presets.load("franka_rest")
    planner = comanip.Planner(model, SolverOptions(threads=1))
    curvature, solver = planner.curvature, planner.solver
    gradient = curvature._functions(planner.problem)[0]  # uncompiled: its Jacobian is built from the graph
    exact_hessian = gradient.factory("exact_hessian", gradient.name_in(), ["jac:grad:x"])
    for k, problem in enumerate([p for p in workspace.load("franka_rest") if not p.moving][:args.problems]):
        if args.cold:
            params = ReachParameters(problem.start, problem.goal, problem.width)
            guess = planner.starts.guesses(params, None)[0]
        else:
            first = planner.solve(problem.start, problem.goal, problem.width)
            params = ReachParameters(problem.start, problem.warm_goal, problem.width)
            guess = planner.starts.guesses(params, first)[0]

        def hessian(data, params=params):
            size = data.x.size
            return np.asarray(exact_hessian(data.x, params.start, params.goal, params.width,
                                            *curvature._speed_weights)).reshape(size, size)

        started = time.perf_counter()
        hessian(curvature.evaluate(np.ravel(guess), params).data)
        seconds = time.perf_counter() - started
        approximate = solver.newton_solve(guess, params, np.inf, curvature).advance(solver.max_iterations)
        exact = newton_minimize(lambda x: curvature.evaluate(x, params), hessian, np.ravel(guess), *solver.torque_bounds,
                                max_iterations=200, tolerance=solver.tolerance, secant=False,
                                constraints=solver.limits.for_newton(curvature), constraint_tolerance=LIMIT_TOLERANCE,
                                value=lambda x: curvature.value_and_data(x, params))
        print(f"problem {k} ({'cold' if args.cold else 'warm'}, {problem.describe()}): approximate Hessian "
              f"{approximate.nit} iterations, f {approximate.fun:.10f}, {approximate.status.value}; exact Hessian "
              f"{exact.nit} iterations, f {exact.fun:.10f}, {exact.status.value}; one exact Hessian {seconds:.1f} s",
              flush=True)


if __name__ == "__main__":
    main()
