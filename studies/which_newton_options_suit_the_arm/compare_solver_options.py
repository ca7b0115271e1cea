"""How the arm's Newton options trade solve time against the plan: ``hessian_refresh`` and ``arm_tolerance``.

    .venv/bin/python -m studies.which_newton_options_suit_the_arm.compare_solver_options [--goals 16] [--preset franka_rest]
        [--variants "1,1e-8 3,1e-8 1,1e-6 3,1e-6 3,1e-5"]

Problems as in studies/do_two_checkouts_plan_the_same_arm_reaches/compare_checkouts.py (``--goals`` points 0.15–0.3 m from the ready pose in uniformly drawn
directions, seed 0): per goal one cold solve from rest at the ready pose, then one warm solve to the goal moved
by up to 5 cm per axis (seed 1), warm-started from that variant's cold plan. Each variant ``k,tol`` is a planner
with ``SolverOptions(hessian_refresh=k, arm_tolerance=tol)``; the variants take turns goal by goal in one
process, so the machine's load falls on all alike. The first variant is the reference of the difference columns.

Per variant and kind of solve (cold, warm): median solve time (ms), total Newton iterations and Hessian
assemblies, successes, the largest relative difference of J from the reference's plan to the same goal, and the
largest distance (mm) between the two plans' mean hand positions at the same step.
"""

from __future__ import annotations

import argparse

import numpy as np

import comanip
from comanip.planning.planner import SolverOptions

from benchmarks.franka_rest import goal_offsets  # noqa: E402


def counting_planner(model, refresh: int, tolerance: float) -> tuple[comanip.Planner, list]:
    """A planner with the variant's options, and the list its Hessian assemblies append to."""
    planner = comanip.Planner(model, SolverOptions(hessian_refresh=refresh, arm_tolerance=tolerance))
    assemblies = []
    curvature = planner.curvature
    assemble = curvature.hessian
    curvature.hessian = lambda data: assemblies.append(1) or assemble(data)
    return planner, assemblies


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--goals", type=int, default=16)
    parser.add_argument("--preset", default="franka_rest")
    parser.add_argument("--variants", default="1,1e-8 3,1e-8 1,1e-6 3,1e-6 3,1e-5",
                        help="space-separated hessian_refresh,arm_tolerance pairs; the first is the reference")
    args = parser.parse_args(argv)
    variants = [(int(k), float(tol)) for k, tol in (pair.split(",") for pair in args.variants.split())]
    model = comanip.presets.load(args.preset)
    planners = [counting_planner(model, k, tol) for k, tol in variants]
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    origin = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    offsets = goal_offsets(args.goals, np.random.default_rng(0))
    shifts = np.random.default_rng(1).uniform(-0.05, 0.05, size=offsets.shape)
    rows = {(v, kind): [] for v in range(len(variants)) for kind in ("cold", "warm")}
    for offset, shift in zip(offsets, shifts):
        for v, (planner, assemblies) in enumerate(planners):
            for kind, goal, warm in (("cold", origin + offset, None), ("warm", origin + offset + shift, "cold")):
                before = len(assemblies)
                plan = planner.solve(start, goal, warm_start=rows[(v, "cold")][-1]["plan"] if warm else None)
                rows[(v, kind)].append({"plan": plan, "assemblies": len(assemblies) - before})
    print(f"{args.preset}, {args.goals} goals; reference: hessian_refresh={variants[0][0]}, arm_tolerance={variants[0][1]:g}\n")
    print("| hessian_refresh | arm_tolerance | solve | median ms | iterations | Hessian assemblies | ok | max relative J "
          "difference | max hand-path distance (mm) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for v, (k, tol) in enumerate(variants):
        for kind in ("cold", "warm"):
            mine, ref = rows[(v, kind)], rows[(0, kind)]
            dJ = max(abs(a["plan"].objective - b["plan"].objective) / abs(b["plan"].objective) for a, b in zip(mine, ref))
            hand = max(1e3 * np.max(np.linalg.norm(a["plan"].ee_mean - b["plan"].ee_mean, axis=1)) for a, b in zip(mine, ref))
            print(f"| {k} | {tol:g} | {kind} | {1e3 * np.median([r['plan'].solve_time for r in mine]):.0f} "
                  f"| {sum(r['plan'].iterations for r in mine)} | {sum(r['assemblies'] for r in mine)} "
                  f"| {sum(r['plan'].success for r in mine)}/{len(mine)} | {dJ:.1e} | {hand:.3f} |", flush=True)


if __name__ == "__main__":
    main()
