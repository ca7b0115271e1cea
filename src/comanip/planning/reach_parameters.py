"""What one solve of the reach problem is for: its start, goal and width (:class:`ReachParameters`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class ReachParameters:
    """The parameters of one reach: start state s_0 (nx,) (m and m/s, or rad and rad/s; activation forces),
    goal g (d,) m, width w (m)."""

    start: np.ndarray
    goal: np.ndarray
    width: float
    vector: np.ndarray = field(init=False, repr=False, compare=False)
    """[s_0; g; w] (nx + d + 1,): the parameter vector of the problem's compiled functions."""

    def __post_init__(self):
        start, goal = np.asarray(self.start, dtype=float), np.asarray(self.goal, dtype=float)
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "goal", goal)
        object.__setattr__(self, "width", float(self.width))
        object.__setattr__(self, "vector", np.concatenate([start, goal, [self.width]]))
