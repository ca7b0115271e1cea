"""Solved reaches of an arm from its ready pose, shipped with the package, as starts for cold solves.

A nonlinear arm has no symmetry to turn one reach into another (:mod:`comanip.planning.starts.reach_library` does
that for point masses), but most of its reaches start from one pose: the body's ``home_position`` at rest (the
Panda's ready pose). :class:`ArmReachLibrary` keeps plans from there to goals on a cubic grid around the
hand (spacing 7 cm, between 0.12 and 0.33 m from it), so every goal 0.15–0.3 m away has an entry within about
6 cm. A cold solve from the ready pose then starts like a warm solve: from the nearest entries' plans, each
also moved onto the new goal by a joint-space minimum-jerk correction (:func:`retargeted_torques`), ranked
with the minimum-jerk guesses by their objective, which takes several times fewer Newton iterations than the
minimum-jerk starts alone (``benchmarks/cold_quality.py`` checks it; docs/results/speed.md).

A library belongs to one model (its :func:`~comanip.model.model_key`): entries are only initial
guesses, but a guess from another model's optimum can lead to another local optimum. The library of the
``franka_rest`` preset is a file in ``comanip/data/`` (``reach_library_<preset>.npz``, made by ``comanip library``);
:func:`bundled_library` finds the one of a model, if any.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Callable

import numpy as np

from comanip.model import ReachingModel, model_key

GRID_SPACING = 0.07
"""m: spacing of the cubic grid of entry goals; any goal in the shell is within √3/2 of it (6.1 cm) of one."""
SHELL = (0.12, 0.33)
"""m: the entries' distances from the ready pose's hand (the benchmark's goals are 0.15–0.3 m away)."""
CANDIDATE_ENTRIES = 2
"""Nearest entries whose plans (and their retargeted variants) compete as a cold solve's start (on 54 franka_rest
problems the start came from the nearest entry 33 times, the second 18, the third 3, a minimum-jerk guess never)."""
WARM_CANDIDATE_ENTRIES = 1
"""Nearest entries whose plans (and their retargeted variants) compete with a warm start's: on 50 chained warm
franka_rest solves two entries took 500 Newton iterations against one's 508, for five more candidates to evaluate."""
START_TOLERANCE = 1e-9
"""rad, rad/s: largest difference from the library's start for which its entries apply."""
FILE_PREFIX = "reach_library_"


@dataclass(frozen=True)
class ArmReachLibrary:
    """Plans of one arm model from one start at rest (module docstring).

    Attributes:
        model_key: :func:`model_key` of the model the plans were solved for.
        start: the start state [q; qdot] (2n,), rad and rad/s, of every entry.
        width: the goal width (m) the entries were solved at.
        goals: entry goals (E, d), m, task space.
        torques: entry plans' torques (E, H, n), N·m.
    """

    model_key: str
    start: np.ndarray
    width: float
    goals: np.ndarray
    torques: np.ndarray

    def __post_init__(self):
        E = len(self.goals)
        if self.goals.ndim != 2 or self.torques.ndim != 3 or len(self.torques) != E:
            raise ValueError(f"a reach library needs goals (E, d) and torques (E, H, n) with one row per entry; "
                             f"got goals {self.goals.shape} and torques {self.torques.shape}")

    def is_for(self, model: ReachingModel) -> bool:
        """True when the library was solved for ``model`` (equal parameters)."""
        return self.model_key == model_key(model)

    def serves(self, start: np.ndarray) -> bool:
        """True when ``start`` (2n,) has the entries' joint positions (to START_TOLERANCE), at rest or moving (the
        planner superposes a braking move on the entries' plans for a moving start)."""
        n = len(self.start) // 2
        return start.shape == self.start.shape and bool(np.all(np.abs(start[:n] - self.start[:n]) <= START_TOLERANCE))

    def nearest(self, goal: np.ndarray, count: int = CANDIDATE_ENTRIES) -> list[tuple[np.ndarray, np.ndarray]]:
        """(entry goal (d,) m, torques (H, n) N·m) of the ``count`` entries nearest to goal (d,), nearest first."""
        order = np.argsort(np.linalg.norm(self.goals - goal, axis=1))[:count]
        return [(self.goals[i].copy(), self.torques[i].astype(float)) for i in order]

    def save(self, path: str | Path) -> Path:
        """Write the library as a compressed .npz (torques in float32: they are starts, not results)."""
        path = Path(path)
        np.savez_compressed(path, model_key=np.array(self.model_key), start=self.start, width=np.array(self.width),
                            goals=self.goals, torques=self.torques.astype(np.float32))
        return path

    @classmethod
    def load(cls, path: str | Path) -> "ArmReachLibrary":
        """A library written by :meth:`save`."""
        with np.load(path) as data:
            return cls(str(data["model_key"]), data["start"], float(data["width"]), data["goals"], data["torques"])


def grid_goals(hand: np.ndarray, spacing: float = GRID_SPACING, shell: tuple[float, float] = SHELL) -> np.ndarray:
    """Points (E, 3), m, of a cubic grid with ``spacing`` centred on ``hand`` (3,) whose distance from it lies in
    ``shell`` (m), nearest first (ties in grid order)."""
    steps = int(np.floor(shell[1] / spacing))
    axis = spacing * np.arange(-steps, steps + 1)
    offsets = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    distance = np.linalg.norm(offsets, axis=1)
    keep = (distance >= shell[0]) & (distance <= shell[1])
    order = np.argsort(distance[keep], kind="stable")
    return hand + offsets[keep][order]


def bundled_library(model: ReachingModel) -> ArmReachLibrary | None:
    """The library shipped for ``model`` (``comanip/data/reach_library_<name>.npz`` solved for exactly these
    parameters), or None."""
    resource = resources.files("comanip") / "data" / f"{FILE_PREFIX}{model.name}.npz"
    if not resource.is_file():
        return None
    with resources.as_file(resource) as path:
        library = ArmReachLibrary.load(path)
    return library if library.is_for(model) else None


def build_library(model: ReachingModel, solve: Callable, goals: np.ndarray,
                  progress: Callable[[int], None] = lambda done: None) -> ArmReachLibrary:
    """Solve a plan from the body's ready pose at rest to each goal (E, d) at the model's width.

    ``solve(start, goal, warm_start)`` is a planner's solve (``warm_start`` a Plan or None); the first goal is
    solved cold, each later one from the plan of the nearest goal solved so far (warm starts, the planner's
    retargeting, about five times cheaper than a cold search). Goals without a successful plan are left out.
    ``progress(done)`` is called after each goal.
    """
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    solved_goals, plans = [], []
    for k, goal in enumerate(goals):
        warm = None
        if plans:
            warm = plans[int(np.argmin(np.linalg.norm(np.array(solved_goals) - goal, axis=1)))]
        plan = solve(start, goal, warm)
        if plan.success:
            solved_goals.append(np.asarray(goal, dtype=float))
            plans.append(plan)
        progress(k + 1)
    if not plans:
        raise RuntimeError(f"no goal of the {len(goals)} could be planned from the ready pose; no library built")
    return ArmReachLibrary(model_key(model), start, float(model.width), np.array(solved_goals),
                           np.array([plan.torque for plan in plans]))
