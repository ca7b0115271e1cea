"""Joint velocities of one Franka reach before and after the speed cost: the paper's ``franka`` preset
(left) and ``franka_rest`` (right), each solved cold from rest at the ready pose to the same goal.

    PYTHONPATH=src python -m studies.does_franka_rest_end_at_rest.make_franka_rest_figure [--offset 0.15 0.1 -0.1]

Writes docs/figures/franka_joint_velocities.png: every joint's mean speed as a fraction of its limit
(qdot / qdot_max, ±1 dashed), MT (docs/formulation.md §6, the hand has stopped) dotted; prints each plan's largest final joint
speed and the time after MT with a joint at ≥ 95 % of its speed limit.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import comanip  # noqa: E402
from comanip.analysis import settling_motion, speed_metrics  # noqa: E402
from comanip.plots.figure_file import save_figure  # noqa: E402

OUT = Path(__file__).resolve().parents[2] / "docs" / "figures" / "franka_joint_velocities.png"   # shown in the user guide


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--offset", type=float, nargs=3, default=[0.15, 0.1, -0.1], help="goal from the ready pose's hand, m")
    args = parser.parse_args(argv)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
    for ax, name in zip(axes, ("franka", "franka_rest")):
        model = comanip.presets.load(name)
        home = model.body.home_position
        goal = np.asarray(model.body.kinematics_function(home)[0]).ravel() + args.offset
        plan = comanip.Planner(model).solve(np.r_[home, np.zeros(model.n)], goal)
        motion = settling_motion(model, plan)
        movement_time = speed_metrics(plan.t, plan.ee_speed).movement_time
        for j in range(model.n):
            ax.plot(plan.t, plan.mean[:, model.n + j] / model.body.qdot_max[j], label=f"joint {j + 1}")
        ax.axhline(1, color="k", ls="--", lw=0.8)
        ax.axhline(-1, color="k", ls="--", lw=0.8)
        ax.axvline(movement_time, color="k", ls=":", lw=1)
        ax.set_xlabel("t (s)")
        ax.set_title(f"{name}: final max |qdot| {motion.final_joint_speed:.2f} rad/s, "
                     f"{motion.time_at_velocity_limit:.2f} s at a limit after MT", fontsize=8)
        print(f"{name}: {plan.status}, final error {1e3 * plan.final_error:.1f} mm, max final joint speed "
              f"{motion.final_joint_speed:.3f} rad/s, time at a speed limit after MT {motion.time_at_velocity_limit:.3f} s, "
              f"MT {movement_time:.3f} s")
    axes[0].set_ylabel("qdot / qdot_max")
    axes[1].legend(fontsize=7, loc="upper right")
    OUT.parent.mkdir(exist_ok=True)
    save_figure(fig, OUT, f"Panda reach to ready-pose hand + {args.offset} m: joint velocities (MT dotted)")
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
