"""The timing of a model's closed-loop reaches and of a recorded reach, counted alike.

A person executes a reach in closed loop: the model replans every step from what it sees (its ``observation``:
noisy, late), with motor noise on (:func:`comanip.execution.execute_receding_horizon`). ``executions`` such
executions each draw their noise from a generator seeded by ``seed`` and the execution's index, so the same
parameters always give the same reaches and a fit's objective is a function of the parameters alone (common random
numbers). Each execution and each recorded trial is timed by
:func:`comanip.analysis.speed_profile.movement_timing`: the onset and end as recorded movements are cut, the
movement time and t_peak/MT between them.
"""

from __future__ import annotations

import numpy as np

from comanip.analysis.speed_profile import ReachTiming, movement_timing
from comanip.execution.receding_horizon import execute_receding_horizon
from comanip.planning.planner import Planner
from comanip.recordings.trial_files import Trial


def closed_loop_timings(planner: Planner, start: np.ndarray, goal: np.ndarray, width: float, executions: int,
                        seed: int) -> list[ReachTiming]:
    """The timing of each of ``executions`` closed-loop executions from the start state (2n,) to the goal (d,) m with
    width m, each 2·H steps long (time to settle after a reach of the horizon's length)."""
    t = planner.model.h * np.arange(2 * planner.model.H + 1)
    return [movement_timing(t, execute_receding_horizon(planner, start, goal, width, steps=2 * planner.model.H,
                                                        rng=np.random.default_rng([seed, k])).ee_speed)
            for k in range(executions)]


def recorded_timing(trial: Trial) -> ReachTiming:
    """The timing of a recorded trial: its positions linearly resampled onto a uniform grid at its median sample
    step, the speed by central differences, and at rest one step after the last sample (a trial runs from rest to
    rest; a motion-capture trial is cut at its end)."""
    step = float(np.median(np.diff(trial.t)))
    t = np.arange(trial.t[0], trial.t[-1] + 0.5 * step, step)
    position = np.column_stack([np.interp(t, trial.t, axis) for axis in trial.position.T])
    speed = np.linalg.norm(np.gradient(position, step, axis=0), axis=1)
    return movement_timing(np.append(t, t[-1] + step), np.append(speed, 0.0))
