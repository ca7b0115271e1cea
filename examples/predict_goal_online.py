"""Predict where a person is reaching while the reach goes on: feed the observed hand states of a recording,
one at a time, to the online goal estimator and watch its goal estimate (with its 95 % ellipse) settle.

    python examples/predict_goal_online.py      # writes out/examples/predict_goal_online.png

Input: examples/data/observations.csv (columns t_s, q0, q1, qdot0, qdot1: a planar reach toward
[0.3, 0.1] m, one noisy execution of the model's plan, observed every 20 ms for 0.3 s).
"""

import csv

import matplotlib.pyplot as plt
import numpy as np

import comanip
from _common import DATA, figure_path

with open(DATA / "observations.csv", newline="") as file:
    rows = [{key: float(value) for key, value in row.items()} for row in csv.DictReader(file)]
times = np.array([row["t_s"] for row in rows])                        # s since the reach started
positions = np.array([[row["q0"], row["q1"]] for row in rows])        # m
velocities = np.array([[row["qdot0"], row["qdot1"]] for row in rows])  # m/s

model = comanip.presets.planar()
# The estimator builds a family of the model's reaches once (a second or two), then updates in milliseconds.
# The task says the goal is somewhere around [0.25, 0] m, give or take 10 cm.
online = comanip.OnlineGoalEstimator(model, np.zeros(4), prior_goal=[0.25, 0.0], prior_std=0.1)

estimates = []
for t, position, velocity in zip(times[1:], positions[1:], velocities[1:]):   # t = 0 is the start itself
    estimate = online.update(t, position, velocity)
    estimates.append(estimate)
    print(f"t = {t:.2f} s: goal {np.round(estimate.goal, 3)} m, status {estimate.status}")

fig, (space_ax, error_ax) = plt.subplots(1, 2, figsize=(10, 4))
space_ax.plot(positions[:, 0], positions[:, 1], "k.-", label="observed hand")
colors = plt.cm.viridis(np.linspace(0, 1, len(estimates)))
for estimate, color in zip(estimates[::3], colors[::3]):
    values, vectors = np.linalg.eigh(estimate.goal_covariance)
    angle = np.linspace(0, 2 * np.pi, 60)
    ellipse = vectors @ (np.sqrt(5.991 * values)[:, None] * np.array([np.cos(angle), np.sin(angle)]))  # 95 %
    space_ax.plot(estimate.goal[0] + ellipse[0], estimate.goal[1] + ellipse[1], color=color, lw=0.8)
    space_ax.plot(*estimate.goal, "o", color=color, ms=4)
space_ax.plot(0.3, 0.1, "r*", ms=12, label="true goal")
space_ax.set(xlabel="x (m)", ylabel="y (m)", title="goal estimates (95 % ellipses)", aspect="equal")
space_ax.legend(fontsize=8)
errors = [np.linalg.norm(e.goal - [0.3, 0.1]) * 1000 for e in estimates]
error_ax.semilogy(times[1:], errors, "o-")
error_ax.set(xlabel="observed up to t (s)", ylabel="goal error (mm)", title="error of the estimate")
fig.tight_layout()
fig.savefig(figure_path("predict_goal_online"), dpi=120)
print("wrote", figure_path("predict_goal_online"))
