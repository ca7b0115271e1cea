"""Seeded problem sets that sample each preset's workspace, kept in ``benchmarks/workspace/<preset>.json``.

    .venv/bin/python benchmarks/workspace.py [--presets planar,franka] [--problems 200] [--arm-problems 60]

writes the sets again (the same files for the same seed and NumPy). The solve-time benchmarks
(``solve_times.py``'s ``*_workspace_*`` cases, ``point_mass_vs_ipopt.py``, ``cold_quality.py --workspace``) read
them, so every checkout compared solves the same problems.

A problem: a start state s0 = [q; qdot] (2n,), a goal (d,) and a width w (m), and a second goal for a warm solve
from the first goal's plan.

- Point masses: the start at the origin; goals 0.05–0.8 m away (uniform) in uniformly drawn directions; widths
  log-uniform over 5–50 mm; every other start moving, at a speed uniform over 0–1 m/s in a uniform direction.
- Arms: the start at the ready pose (``body.home_position``); goals 0.1–0.3 m from its hand in uniform directions,
  kept only if the inverse kinematics reaches them within the width; widths log-uniform over 5–50 mm; every
  fourth start moving, the hand at a speed uniform over 0–1 m/s in a uniform direction (joint velocities by the
  Jacobian's pseudo-inverse).
- The warm goal: the goal moved by up to 5 cm per axis (uniform; for an arm, reachable too).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

FOLDER = Path(__file__).resolve().parent / "workspace"
POINT_MASS_PRESETS = ("planar", "cartesian", "human", "human_cartesian")
ARM_PRESETS = ("franka", "franka_rest")
SEED = 36
POINT_MASS_DISTANCES, ARM_DISTANCES = (0.05, 0.8), (0.1, 0.3)
"""Goal distances (m) from the start's hand position, uniform."""
WIDTHS = (0.005, 0.05)
"""Goal widths w (m), log-uniform."""
TOP_SPEED = 1.0
"""Largest start speed of the hand (m/s), uniform from zero."""
WARM_MOVE = 0.05
"""A warm goal's move from the problem's goal, uniform per axis (m)."""


@dataclass(frozen=True)
class WorkspaceProblem:
    """One problem of a set: start (nx,) [q; qdot] in m, m/s (rad, rad/s for joints), goal (d,) m, width w (m),
    warm_goal (d,) m; distance (m) from the start's hand to the goal and hand speed (m/s) at the start, for
    reading the results."""

    start: np.ndarray
    goal: np.ndarray
    width: float
    warm_goal: np.ndarray
    distance: float
    speed: float

    @property
    def moving(self) -> bool:
        return self.speed > 0.0

    def describe(self) -> str:
        """A short label: distance, width, start speed."""
        return f"D {self.distance:.2f} m, w {1e3 * self.width:.1f} mm, v0 {self.speed:.2f} m/s"


def _direction(rng: np.random.Generator, d: int) -> np.ndarray:
    direction = rng.normal(size=d)
    return direction / np.linalg.norm(direction)


def _width(rng: np.random.Generator) -> float:
    return float(np.exp(rng.uniform(*np.log(WIDTHS))))


def point_mass_problems(model, count: int, seed: int = SEED) -> list[WorkspaceProblem]:
    """The point-mass set (module docstring)."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(count):
        distance, width = rng.uniform(*POINT_MASS_DISTANCES), _width(rng)
        goal = distance * _direction(rng, model.d)
        speed = rng.uniform(0.0, TOP_SPEED) if k % 2 else 0.0
        start = np.r_[np.zeros(model.n), speed * _direction(rng, model.n)]
        warm_goal = goal + rng.uniform(-WARM_MOVE, WARM_MOVE, model.d)
        out.append(WorkspaceProblem(start, goal, width, warm_goal, float(distance), float(speed)))
    return out


def arm_problems(model, count: int, seed: int = SEED) -> list[WorkspaceProblem]:
    """The arm set (module docstring): goals the arm reaches within their width from the ready pose."""
    body, rng, out = model.body, np.random.default_rng(seed), []
    home = body.home_position
    hand, jacobian = (np.asarray(value) for value in body.kinematics_function(home)[:2])
    hand = hand.ravel()

    def reachable(goal, width):
        q = body.inverse_kinematics(goal, home)
        return np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - goal) <= width

    while len(out) < count:
        distance, width = rng.uniform(*ARM_DISTANCES), _width(rng)
        goal = hand + distance * _direction(rng, model.d)
        warm_goal = goal + rng.uniform(-WARM_MOVE, WARM_MOVE, model.d)
        speed = rng.uniform(0.0, TOP_SPEED) if len(out) % 4 == 3 else 0.0
        hand_velocity = speed * _direction(rng, model.d)
        if not (reachable(goal, width) and reachable(warm_goal, width)):
            continue
        start = np.r_[home, np.linalg.pinv(jacobian) @ hand_velocity]
        out.append(WorkspaceProblem(start, goal, width, warm_goal, float(distance), float(speed)))
    return out


def write(preset: str, count: int, seed: int = SEED) -> Path:
    """Draw the preset's set and write it to FOLDER/<preset>.json."""
    import comanip

    model = comanip.presets.load(preset)
    problems = (point_mass_problems if model.body.is_linear else arm_problems)(model, count, seed)
    FOLDER.mkdir(exist_ok=True)
    path = FOLDER / f"{preset}.json"
    rows = [{"start": p.start.tolist(), "goal": p.goal.tolist(), "width": p.width, "warm_goal": p.warm_goal.tolist(),
             "distance": p.distance, "speed": p.speed} for p in problems]
    lines = ",\n".join(json.dumps(row) for row in rows)  # one problem a line
    path.write_text(f'{{"preset": "{preset}", "seed": {seed}, "problems": [\n{lines}\n]}}\n')
    return path


def load(preset: str) -> list[WorkspaceProblem]:
    """The preset's set as written by :func:`write`."""
    rows = json.loads((FOLDER / f"{preset}.json").read_text())["problems"]
    return [WorkspaceProblem(np.array(r["start"]), np.array(r["goal"]), float(r["width"]), np.array(r["warm_goal"]),
                             float(r["distance"]), float(r["speed"])) for r in rows]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--presets", default=",".join(POINT_MASS_PRESETS + ARM_PRESETS))
    parser.add_argument("--problems", type=int, default=200, help="problems per point-mass preset (default: %(default)s)")
    parser.add_argument("--arm-problems", type=int, default=60, help="problems per arm preset (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=SEED)
    args = parser.parse_args(argv)
    for preset in args.presets.split(","):
        count = args.arm_problems if preset in ARM_PRESETS else args.problems
        print(write(preset, count, args.seed))


if __name__ == "__main__":
    main()
