"""Do two versions of the code plan the same Panda reaches? Per goal, J, iterations, status and torques of both.

    .venv/bin/python -m studies.do_two_checkouts_plan_the_same_arm_reaches.compare_checkouts --compare REF [--presets franka_rest,franka] [--goals 8]
    .venv/bin/python -m studies.do_two_checkouts_plan_the_same_arm_reaches.compare_checkouts --compare . --perturb 2.2e-16

Goals as in franka_rest.py (``--goals`` points 0.15–0.3 m from the ready pose in uniformly drawn directions, seed
0): per goal one cold solve from rest at the ready pose, then one warm solve to the goal moved by up to 5 cm per
axis (seed 1), warm-started from the cold plan. This checkout's code and REF's (another checkout, e.g. a
worktree at main) each run in their own process. ``--perturb EPS`` multiplies REF's Panda Hessian by (1 + EPS):
with REF this checkout and EPS one rounding unit it shows how far rounding alone moves the plans.

Per plan: J of both, their relative difference, iterations and statuses of both, the largest torque
difference (N·m) and the largest distance between the two mean hand paths (mm, over the H+1 steps). Solve times
are left to solve_times.py.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

import comanip

ROOT = Path(__file__).resolve().parents[2]


def plans(presets: list[str], goals: int, perturb: float) -> dict:
    """{"preset/goal/cold|warm": {J, iterations, status, torque}} with this process's comanip."""
    from benchmarks.franka_rest import goal_offsets

    if perturb:
        from comanip.planning.linearised_curvature import LinearisedCurvature

        exact = LinearisedCurvature.hessian
        LinearisedCurvature.hessian = lambda self, data: exact(self, data) * (1 + perturb)
    out = {}
    for preset in presets:
        planner = comanip.Planner(comanip.presets.load(preset))
        model = planner.model
        start = np.r_[model.body.home_position, np.zeros(model.n)]
        origin = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
        offsets = goal_offsets(goals, np.random.default_rng(0))
        shifts = np.random.default_rng(1).uniform(-0.05, 0.05, size=offsets.shape)
        for k, (offset, shift) in enumerate(zip(offsets, shifts)):
            cold = planner.solve(start, origin + offset)
            warm = planner.solve(start, origin + offset + shift, warm_start=cold)
            for kind, plan in (("cold", cold), ("warm", warm)):
                out[f"{preset}/{k}/{kind}"] = {"J": plan.objective, "iterations": int(plan.iterations),
                                               "status": str(plan.status), "torque": plan.torque.tolist(),
                                               "hand": plan.ee_mean.tolist()}
    return out


def run(src: Path, presets: list[str], goals: int, perturb: float) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", __spec__.name, "--presets", ",".join(presets), "--goals", str(goals),
                             "--perturb", repr(perturb), "--plans"], env={**os.environ, "PYTHONPATH": str(src)},
                            cwd=ROOT, stdout=subprocess.PIPE, text=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--compare", type=Path, default=None, help="the other checkout (its src/ is imported)")
    parser.add_argument("--presets", default="franka_rest,franka")
    parser.add_argument("--goals", type=int, default=8)
    parser.add_argument("--perturb", type=float, default=0.0, help="scale REF's Panda Hessian by 1 + PERTURB")
    parser.add_argument("--plans", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    presets = [p for p in args.presets.split(",") if p]
    if args.plans:
        print(json.dumps(plans(presets, args.goals, args.perturb)))
        return
    if args.compare is None:
        raise SystemExit("--compare REF is required: the checkout to compare this one with")
    # both codes at once (the plans, not their times, are compared)
    new, ref = run(ROOT / "src", presets, args.goals, 0.0), run(args.compare.resolve() / "src", presets,
                                                                        args.goals, args.perturb)
    new, ref = (json.loads(p.communicate()[0].strip().splitlines()[-1]) for p in (new, ref))
    print("| plan | J new | J ref | relative difference | iterations new / ref | status new / ref | max torque difference (N·m) "
          "| max hand-path distance (mm) |")
    print("|---|---|---|---|---|---|---|---|")
    for key, a in new.items():
        b = ref[key]
        torque = np.abs(np.array(a["torque"]) - np.array(b["torque"])).max()
        print(f"| {key} | {a['J']:.6f} | {b['J']:.6f} | {abs(a['J'] - b['J']) / abs(b['J']):.1e} | "
              f"{a['iterations']} / {b['iterations']} | {a['status']} / {b['status']} | {torque:.1e} | {hand_distance(a, b):.3f} |")
    for preset in presets:
        keys = [key for key in new if key.startswith(preset + "/")]
        same = sum(new[k]["iterations"] == ref[k]["iterations"] and new[k]["status"] == ref[k]["status"] for k in keys)
        worst = max(abs(new[k]["J"] - ref[k]["J"]) / abs(ref[k]["J"]) for k in keys)
        farthest = max(hand_distance(new[k], ref[k]) for k in keys)
        print(f"\n{preset}: {same}/{len(keys)} plans with the same iterations and status; largest relative J "
              f"difference {worst:.1e}; largest hand-path distance {farthest:.3f} mm; iterations new "
              f"{sum(new[k]['iterations'] for k in keys)}, ref {sum(ref[k]['iterations'] for k in keys)}")


def hand_distance(a: dict, b: dict) -> float:
    """The largest distance (mm) between two plans' mean hand positions at the same step."""
    return 1e3 * float(np.max(np.linalg.norm(np.array(a["hand"]) - np.array(b["hand"]), axis=1)))


if __name__ == "__main__":
    main()
