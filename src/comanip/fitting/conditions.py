"""Grouping trials into conditions: trials with one goal, one width and nearly one start share a plan.

Each evaluation of the fit plans one reach per condition, not per trial. A trial joins a condition when
its goal and width are equal and its start lies within a tolerance of the condition's first trial's
start; the condition starts from the mean start of its trials. A trial's predicted mean is the
condition's, moved by the trial's start offset (exact for the mean of a point mass under the plan's
torques: its dynamics are linear and a rest state stays at rest; for an arm an approximation).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.recordings.trial_files import Trial
from comanip.model import ReachingModel


@dataclass(frozen=True)
class Condition:
    """Trials planned as one reach."""

    start: np.ndarray
    """Start position (d,), m: the mean first sample of the trials."""
    goal: np.ndarray
    """Goal position (d,), m."""
    width: float
    """Goal width w (m)."""
    trials: tuple[int, ...]
    """Indices of the trials (into the list given to :func:`group_conditions`)."""

    def start_state(self, model: ReachingModel) -> np.ndarray:
        """The plan's start s_0 = [q; 0] (2n,), at rest, with q the inverse kinematics of the start position
        (from the body's home position)."""
        q = model.body.inverse_kinematics(self.start, model.body.home_position)
        return np.concatenate([q, np.zeros(model.n)])


def group_conditions(trials: list[Trial], start_tolerance: float) -> list[Condition]:
    """Conditions of the trials, in order of first appearance; start_tolerance in m (≥ 0)."""
    members: list[list[int]] = []
    for k, trial in enumerate(trials):
        for group in members:
            first = trials[group[0]]
            if (np.array_equal(first.goal, trial.goal) and first.width == trial.width
                    and np.linalg.norm(first.start - trial.start) <= start_tolerance):
                group.append(k)
                break
        else:
            members.append([k])
    return [Condition(np.mean([trials[k].start for k in group], axis=0), trials[group[0]].goal,
                      trials[group[0]].width, tuple(group)) for group in members]
