"""Plan one reach with the paper's planar model and draw the predicted hand: its mean path with the
uncertainty of the hand around it, and its speed over time.

    python examples/plan_a_reach.py        # writes out/examples/plan_a_reach.png

The planner builds the optimal-control problem once (CasADi) and solves it for any start, goal and width.
"""

import matplotlib.pyplot as plt
import numpy as np

import comanip
from _common import figure_path

model = comanip.presets.planar()            # 2 kg point mass in the plane, h = 0.02 s, H = 30 steps
planner = comanip.Planner(model)            # built once ...
start = np.zeros(4)                         # [x, y, xdot, ydot]: at rest at the origin (m, m/s)

# ... solved many times: three goals 0.3 m away, and a narrower target for the first one.
goals = {"0.3 m ahead, w = 2 cm": ([0.3, 0.0], 0.02),
         "0.3 m ahead, w = 5 mm": ([0.3, 0.0], 0.005),
         "to the side, w = 2 cm": ([0.2, 0.2], 0.02)}
plans = {}
for label, (goal, width) in goals.items():
    plan = planner.solve(start, goal, width)   # never raises: read plan.success and plan.status
    print(f"{label}: {plan.status}, ends {np.linalg.norm(plan.ee_mean[-1] - goal) * 1000:.1f} mm from the goal")
    plans[label] = plan

fig, (path_ax, speed_ax) = plt.subplots(1, 2, figsize=(10, 4))
for label, plan in plans.items():
    line, = path_ax.plot(plan.ee_mean[:, 0], plan.ee_mean[:, 1], label=label)
    for i in range(0, len(plan.t), 5):   # one standard deviation of the hand, every fifth step
        values, vectors = np.linalg.eigh(plan.ee_cov[i])
        angle = np.linspace(0, 2 * np.pi, 40)
        ellipse = vectors @ (np.sqrt(values)[:, None] * np.array([np.cos(angle), np.sin(angle)]))
        path_ax.plot(plan.ee_mean[i, 0] + ellipse[0], plan.ee_mean[i, 1] + ellipse[1], color=line.get_color(), lw=0.5)
    speed_ax.plot(plan.t, plan.ee_speed, color=line.get_color(), label=label)
path_ax.set(xlabel="x (m)", ylabel="y (m)", title="mean hand path, ±1 SD", aspect="equal")
speed_ax.set(xlabel="t (s)", ylabel="hand speed (m/s)", title="speed profile")
path_ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(figure_path("plan_a_reach"), dpi=120)
print("wrote", figure_path("plan_a_reach"))
