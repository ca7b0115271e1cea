"""Hand a reach over from the robot to the person where people switch from their fast first movement to
their slow corrective one: predict that transition point, then ramp the robot's stiffness to zero there.

    python examples/handover_schedule.py       # writes out/examples/handover_schedule.png

The transition model is a Gaussian process fitted on the shipped transition data (the peak of the hand's
spread across the path, over reaches of many distances and widths); the robot leads along the planned reach
at 400 N/m until the planned hand is within the predicted distance of the goal, then lets go along a 0.2 s
raised cosine.
"""

import matplotlib.pyplot as plt
import numpy as np

import comanip
from comanip.multicomponent.handover import plan_handover
from _common import figure_path

transition = comanip.TransitionModel()          # fitted on src/comanip/data/transition_planar.csv
for distance in (0.2, 0.35, 0.5):
    mean, std = transition.predict(distance=distance, width=0.02)
    print(f"a {distance} m reach to a 2 cm goal switches {float(mean):.3f} ± {float(std):.3f} m before the goal")

planner = comanip.Planner(comanip.presets.cartesian())       # the robot's model of the person's reach (3-D)
goals = {"near": [0.3, 0.1, 0.0], "far": [0.45, 0.2, 0.1]}
schedules = {}
for label, goal in goals.items():
    plan = planner.solve(np.zeros(6), goal)
    schedule = plan_handover(plan, transition, ramp_time=0.2, rate=1000.0)   # sampled at the controller's 1 kHz
    print(f"{label}: hands over at t = {schedule.transition_time:.2f} s, "
          f"{schedule.transition_distance:.3f} m before the goal ({schedule.status})")
    schedules[label] = schedule

fig, (stiffness_ax, distance_ax) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
for label, schedule in schedules.items():
    distance = np.linalg.norm(schedule.rest_position - schedule.goal, axis=1)
    line, = stiffness_ax.plot(schedule.t, schedule.stiffness, label=label)
    distance_ax.plot(schedule.t, distance, color=line.get_color())
    distance_ax.axhline(schedule.transition_distance, color=line.get_color(), ls=":", lw=0.8)
stiffness_ax.set(ylabel="robot stiffness (N/m)", title="authority handover schedule")
distance_ax.set(xlabel="t (s)", ylabel="rest position to goal (m)")
stiffness_ax.legend()
fig.tight_layout()
fig.savefig(figure_path("handover_schedule"), dpi=120)
print("wrote", figure_path("handover_schedule"))
