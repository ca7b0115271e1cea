"""Fit the model's motor noise kappa to recorded reaches, then compare the recordings with the fitted model's
prediction: mean path and ±2 SD band of the hand across the path.

    python examples/fit_to_recordings.py       # writes out/examples/fit_to_recordings.png

Input: examples/data/recordings/ (one CSV per reach: trial, t, x, y, goal_x, goal_y, width; six planar
reaches to three goals, made with kappa = 0.03 and 1 mm of measurement noise). The fit starts from the planar
preset's kappa = 0.01 and should land near 0.03. Format and method: docs/fitting.md.
"""

import matplotlib.pyplot as plt
import numpy as np

import comanip
from comanip.fitting import load_recordings
from _common import DATA, SMALL, figure_path

recordings = DATA / "recordings"
model = comanip.presets.planar()
result = comanip.fit_model(model, recordings, parameters=["kappa"],
                           max_evaluations=12 if SMALL else 60, progress=False)
print(f"status {result.status}: kappa = {result.values['kappa']:.4f} ± {result.std_errors['kappa']:.4f}"
      f" (started at {model.kappa})")
fitted = model.replace(**result.values)

planner = comanip.Planner(fitted)
fig, ax = plt.subplots(figsize=(6, 5))
trials = load_recordings(recordings)
for trial in trials:
    ax.plot(trial.position[:, 0], trial.position[:, 1], color="0.5", lw=0.8)
for goal in {tuple(trial.goal) for trial in trials}:
    plan = planner.solve(np.zeros(4), goal, trials[0].width)
    direction = np.asarray(goal) / np.linalg.norm(goal)
    across = np.array([-direction[1], direction[0]])
    spread = 2 * np.sqrt(np.einsum("i,kij,j->k", across, plan.ee_cov, across))   # 2 SD across the path (m)
    ax.plot(*plan.ee_mean.T, "C0")
    for sign in (-1, 1):
        edge = plan.ee_mean + sign * spread[:, None] * across
        ax.plot(*edge.T, "C0--", lw=0.8)
ax.plot([], [], color="0.5", label="recorded reaches")
ax.plot([], [], "C0", label=f"fitted model (kappa = {fitted.kappa:.3f}): mean, ±2 SD")
ax.set(xlabel="x (m)", ylabel="y (m)", aspect="equal", title="recordings against the fitted model")
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(figure_path("fit_to_recordings"), dpi=120)
print("wrote", figure_path("fit_to_recordings"))
