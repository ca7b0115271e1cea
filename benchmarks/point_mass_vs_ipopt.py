"""Point-mass solves against CasADi + IPOPT on the same problems, with another checkout's code in the same run.

    PYTHONPATH=src .venv/bin/python benchmarks/point_mass_vs_ipopt.py --compare ../main [--presets planar] [--repeats 100]

Per preset, the problems of its sampled workspace set (benchmarks/workspace.py: goals 0.05–0.8 m away in every
direction, widths 5–50 mm, half the starts moving at up to 1 m/s), in three cases: warm (each problem's plan to its
goal, untimed, then the timed solve to its warm goal up to 5 cm away, warm-started from that plan by the same
solver), cold (the problems at rest, no warm start) and cold_moving (the problems from a moving start). Cold solves
are a long-lived planner's: each planner has solved the cold problems once before, untimed, which fills its reach
library as its first solves would. The same problems for every solver and every checkout.

Each checkout runs in its own process (its ``src`` first on PYTHONPATH) holding two planners for the model: the
structured Newton method, compiled (``SolverOptions(compile=True)``), and the reference, IPOPT on the same
single-shooting problem with CasADi's exact Hessian (``SolverOptions(method="ipopt")``, which starts from the same
initial guesses). Solves run in blocks of ``--block`` consecutive problems by one solver of one process (a
solver called again and again, as in a control loop, with its data in the processor's caches), and the blocks
take turns: block b by each process's Newton method and IPOPT (which goes first alternates), then block b + 1,
so every number of a row sees the same machine load within a few tens of milliseconds. Each planner's first
solve (compiling, if needed) is not timed. The processes run with ``OPENBLAS_NUM_THREADS=1`` and
``OMP_NUM_THREADS=1`` (``--blas-threads``): the planner limits its own BLAS to one thread anyway, while IPOPT's
linear solver (MUMPS, on CasADi's own OpenBLAS) would otherwise start a thread per core and, on a loaded machine,
wait for them (two to three times slower here), which would flatter the ratio.

Columns: medians and p90 of ``plan.solve_time`` (ms), the ratio of the IPOPT median to the Newton median, and the
objective gap |J_newton − J_ipopt| / |J_ipopt| per problem (its largest value, and on how many problems it is
at most 1e-8), successes of either solver.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import workspace  # noqa: E402  (the sampled problem sets beside this script)
from solve_times import worker_reply  # noqa: E402

CASES = ("warm", "cold", "cold_moving")
SOLVERS = ("newton", "ipopt")
GAP = 1e-8
"""Objective gap (relative) within which two plans count as the same optimum."""


class Problems:
    """One process's planners for a preset and the seeded problems of each case."""

    def __init__(self, preset: str):
        import comanip
        from comanip.planning.planner import SolverOptions

        model = self.model = comanip.presets.load(preset)
        self.planners = {"newton": comanip.Planner(model, SolverOptions(compile=True)),
                         "ipopt": comanip.Planner(model, SolverOptions(method="ipopt"))}
        problems = workspace.load(preset)
        self.problems = {"warm": problems, "cold": [p for p in problems if not p.moving],
                         "cold_moving": [p for p in problems if p.moving]}
        for planner in self.planners.values():  # one-off work, and the reach library a long-lived planner has
            for problem in problems:
                planner.solve(problem.start, problem.goal, problem.width)

    def solve(self, solver: str, case: str, k: int) -> list:
        """Problem k of the case (wrapping around) by the solver ('newton' or 'ipopt'): [seconds, J, success]."""
        planner, problem = self.planners[solver], self.problems[case][k % len(self.problems[case])]
        if case == "warm":
            first = planner.solve(problem.start, problem.goal, problem.width)
            plan = planner.solve(problem.start, problem.warm_goal, problem.width, warm_start=first)
        else:
            plan = planner.solve(problem.start, problem.goal, problem.width)
        return [plan.solve_time, plan.objective, bool(plan.success)]


def serve(preset: str) -> None:
    """Build the planners, say so, then solve each block 'solver case first last' read from stdin and write the
    results as JSON."""
    problems = Problems(preset)
    print(json.dumps({"ready": preset}), flush=True)
    for line in sys.stdin:
        solver, case, first, last = line.split()
        print(json.dumps({"runs": [problems.solve(solver, case, k) for k in range(int(first), int(last))]}), flush=True)


def rows(preset: str, sources: dict[str, Path], repeats: int, block: int, blas_threads: int) -> list[str]:
    threads = {name: str(blas_threads) for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")}
    workers = {label: subprocess.Popen([sys.executable, __file__, "--serve", preset], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                       text=True, env={**os.environ, **threads, "PYTHONPATH": str(src)})
               for label, src in sources.items()}
    for worker in workers.values():
        worker_reply(worker)
    lines = []
    for case in CASES:
        runs = {(label, solver): [] for label in workers for solver in SOLVERS}
        for b, first in enumerate(range(0, repeats, block)):
            last = min(repeats, first + block)
            for label, worker in workers.items():
                for solver in (SOLVERS if b % 2 == 0 else SOLVERS[::-1]):
                    worker.stdin.write(f"{solver} {case} {first} {last}\n")
                    worker.stdin.flush()
                    runs[label, solver] += worker_reply(worker)["runs"]
        for label in workers:
            newton, ipopt = (np.array(runs[label, solver], dtype=float) for solver in SOLVERS)
            gap = np.abs(newton[:, 1] - ipopt[:, 1]) / np.abs(ipopt[:, 1])
            t_n, t_i = 1e3 * newton[:, 0], 1e3 * ipopt[:, 0]
            lines.append(f"| {preset} | {case} | {label} | {np.median(t_n):.3f} | {np.percentile(t_n, 90):.3f} | "
                         f"{np.median(t_i):.3f} | {np.percentile(t_i, 90):.3f} | {np.median(t_i) / np.median(t_n):.1f}× | "
                         f"{gap.max():.1e} | {int(np.sum(gap <= GAP))}/{repeats} | "
                         f"{int(newton[:, 2].sum())}/{int(ipopt[:, 2].sum())} |")
            print(lines[-1], flush=True)
    for worker in workers.values():
        worker.stdin.close()
        worker.wait()
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--presets", default="planar", help="comma-separated point-mass presets (default: %(default)s)")
    parser.add_argument("--repeats", type=int, default=100, help="problems per case (default: %(default)s)")
    parser.add_argument("--block", type=int, default=10, help="consecutive problems per solver and turn (default: %(default)s)")
    parser.add_argument("--blas-threads", type=int, default=1, help="OpenBLAS and OpenMP threads of the processes (default: %(default)s)")
    parser.add_argument("--compare", type=Path, default=None, help="another checkout to run side by side (its src/)")
    parser.add_argument("--serve", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.serve:
        serve(args.serve)
        return
    sources = {"new": Path(__file__).resolve().parents[1] / "src"}
    if args.compare is not None:
        sources["ref"] = args.compare.resolve() / "src"
    print(f"load average at start: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    print("| preset | case | code | Newton median ms | Newton p90 ms | IPOPT median ms | IPOPT p90 ms | IPOPT / Newton "
          f"| largest J gap | gaps ≤ {GAP:g} | ok Newton / IPOPT |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for preset in args.presets.split(","):
        rows(preset, sources, args.repeats, args.block, args.blas_threads)
    print(f"load average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
