"""Write the example inputs in this folder, so that every one of them can be rebuilt.

    PYTHONPATH=src python examples/data/make_example_data.py

They are made by the model itself (noisy open-loop executions of its plans), so the examples have a known
answer: the observed reach goes to [0.3, 0.1] m, the recordings were made with kappa = 0.03, the hand CSV
reaches for [0.35, 0.1, 0.05] m. Formats: docs/data_formats.md. The recorded arm reaches in ``arm_reaches/`` are
people's, copied, not made here (``arm_reaches/tathum/SOURCE.md``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import comanip
from comanip.belief import sample_trajectories

HERE = Path(__file__).resolve().parent


def noisy_reach(model, goal, seed):
    """One execution of the model's plan to goal from rest: times (H+1,), states (H+1, 2n)."""
    start = np.zeros(2 * model.n)
    plan = comanip.Planner(model).solve(start, goal, model.width)
    states = sample_trajectories(model.body, model.h, model.kappa, start, plan.torque, 1, np.random.default_rng(seed),
                                 model.noise)[0]
    return plan.t, states


def write_observations() -> None:
    """observations.csv: a planar reach toward [0.3, 0.1] m, observed every step for its first 0.3 s."""
    times, states = noisy_reach(comanip.presets.planar(), [0.3, 0.1], seed=1)
    keep = times <= 0.3 + 1e-9
    rows = ["t_s,q0,q1,qdot0,qdot1"] + [",".join(f"{v:.6g}" for v in (t, *s)) for t, s in zip(times[keep], states[keep])]
    (HERE / "observations.csv").write_text("\n".join(rows) + "\n")


def write_recordings() -> None:
    """recordings/: six planar reaches (two per goal) made with kappa = 0.03, sampled every 20 ms with 1 mm noise."""
    model = comanip.presets.planar().replace(kappa=0.03)
    folder = HERE / "recordings"
    folder.mkdir(exist_ok=True)
    rng = np.random.default_rng(7)
    goals = [(0.3, 0.0), (0.15, 0.15), (0.25, -0.1)]
    for k in range(6):
        goal = goals[k % len(goals)]
        times, states = noisy_reach(model, goal, seed=10 + k)
        positions = states[:, :2] + rng.normal(0.0, 1e-3, size=(len(times), 2))
        rows = ["trial,t,x,y,goal_x,goal_y,width"] + [
            f"reach{k + 1},{t:.3f},{x:.5f},{y:.5f},{goal[0]},{goal[1]},{model.width}" for t, (x, y) in zip(times, positions)]
        (folder / f"reach{k + 1}.csv").write_text("\n".join(rows) + "\n")


def write_hand() -> None:
    """hand.csv: a Cartesian hand reaching for [0.35, 0.1, 0.05] m, at 100 Hz for 1 s (the node replay's input):
    the model's mean reach, as a tracker would sample it between the model's steps of 55 ms."""
    model = comanip.presets.cartesian()
    plan = comanip.Planner(model).solve(np.zeros(6), [0.35, 0.1, 0.05], model.width)
    grid = np.arange(0.0, 1.0 + 1e-9, 0.01)
    sampled = np.column_stack([np.interp(grid, plan.t, plan.mean[:, j]) for j in range(6)])
    header = "t_s,q0,q1,q2,qdot0,qdot1,qdot2"
    rows = [header] + [",".join(f"{v:.6g}" for v in (t, *s)) for t, s in zip(grid, sampled)]
    (HERE / "hand.csv").write_text("\n".join(rows) + "\n")


if __name__ == "__main__":
    write_observations()
    write_recordings()
    write_hand()
    print("wrote", *sorted(p.name for p in HERE.iterdir() if p.suffix in (".csv", "") and p.name != "__pycache__"))
