"""The timing of a mean reach: the model's, from its closed-loop executions, and the recorded trials', timed alike.

A person executes a reach in closed loop: the model replans every step from what it sees (its ``observation``:
noisy, late), with motor noise on (:func:`comanip.execution.execute_receding_horizon`). ``executions`` such
executions each draw their noise from a generator seeded by ``seed`` and the execution's index, so the same
parameters always give the same reaches and a fit's objective is a function of the parameters alone (common random
numbers). A mean reach is the mean of the reaches' velocities, each reach from its start (t = 0, at rest) and at
rest after its end; its timing is :func:`comanip.analysis.speed_profile.movement_timing`'s (onset and end as
recorded movements are cut), for the model's executions and the recorded trials alike.
"""

from __future__ import annotations

import numpy as np

from comanip.analysis.speed_profile import ReachTiming, movement_timing
from comanip.execution.receding_horizon import execute_receding_horizon
from comanip.planning.planner import Planner
from comanip.recordings.trial_files import Trial


def closed_loop_timing(planner: Planner, start: np.ndarray, goal: np.ndarray, width: float, executions: int,
                       seed: int) -> ReachTiming:
    """The timing of the mean of ``executions`` closed-loop executions from the start state (2n,) to the goal (d,) m
    with width m, each 2·H steps long (time to settle after a reach of the horizon's length)."""
    velocities = [execute_receding_horizon(planner, start, goal, width, steps=2 * planner.model.H,
                                           rng=np.random.default_rng([seed, k])).ee_velocity
                  for k in range(executions)]
    return mean_reach_timing(planner.model.h, np.mean(velocities, axis=0))


def mean_reach_timing(step: float, velocity: np.ndarray) -> ReachTiming:
    """The timing of a mean velocity (K, d) m/s sampled every ``step`` s from the reaches' start."""
    return movement_timing(step * np.arange(len(velocity)), np.linalg.norm(velocity, axis=1))


def recorded_velocities(trials: list[Trial], step: float) -> np.ndarray:
    """The trials' velocities (trials, K, d) m/s on one grid of ``step`` s from each trial's first sample: positions
    interpolated linearly, velocities by central differences, zero after the trial's last sample (a trial runs from
    rest to rest; a motion-capture trial is cut at its end). K covers the longest trial and one step at rest."""
    length = max(trial.t[-1] - trial.t[0] for trial in trials)
    grid = np.arange(0.0, length + 1.5 * step, step)
    velocities = np.zeros((len(trials), len(grid), trials[0].position.shape[1]))
    for k, trial in enumerate(trials):
        t = trial.t - trial.t[0]
        inside = grid <= t[-1] + 1e-12
        if inside.sum() >= 2:   # a trial shorter than one step stays at rest
            position = np.column_stack([np.interp(grid[inside], t, axis) for axis in trial.position.T])
            velocities[k, inside] = np.gradient(position, step, axis=0)
    return velocities
