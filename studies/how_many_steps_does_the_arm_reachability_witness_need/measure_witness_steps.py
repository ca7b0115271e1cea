"""How far a warm Panda solve's reachability witness lands from the goal after 1, 2 and 3 damped least-squares steps.

    .venv/bin/python -m studies.how_many_steps_does_the_arm_reachability_witness_need.measure_witness_steps [--goals 30]

Goals as in solve_times.py's ``franka_rest`` warm row (within ±5 cm per axis of [0.15, 0.1, -0.1] m from the ready
pose's hand, seed 0), each solved warm from the plan before; per goal the distance (mm) of the previous plan's
final hand position from the goal, and the distance left after ``Body.least_squares_inverse_kinematics`` from that
final position with 1, 2 and 3 steps (``planning.planner.WITNESS_STEPS`` is 3; a witness needs ≤ w = 50 mm).
"""

from __future__ import annotations

import argparse

import numpy as np

import comanip


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--goals", type=int, default=30)
    args = parser.parse_args(argv)
    planner = comanip.Planner(comanip.presets.load("franka_rest"))
    body = planner.model.body
    start = np.r_[body.home_position, np.zeros(body.n)]
    base = np.asarray(body.kinematics_function(body.home_position)[0]).ravel() + [0.15, 0.1, -0.1]
    rng = np.random.default_rng(0)
    previous = planner.solve(start, base)

    def distance(q, goal):
        return 1e3 * float(np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - goal))

    rows = []
    for _ in range(args.goals):
        goal = base + rng.uniform(-0.05, 0.05, 3)
        final = previous.mean[-1, : body.n]
        rows.append([distance(final, goal)] + [distance(body.least_squares_inverse_kinematics(goal, final, steps), goal)
                                               for steps in (1, 2, 3)])
        previous = planner.solve(start, goal, warm_start=previous)
    rows = np.array(rows)
    print("| | start | 1 step | 2 steps | 3 steps |\n|---|---|---|---|---|")
    for name, reduce in (("median mm", np.median), ("largest mm", np.max)):
        print(f"| {name} | " + " | ".join(f"{reduce(rows[:, k]):.4g}" for k in range(4)) + " |")


if __name__ == "__main__":
    main()
