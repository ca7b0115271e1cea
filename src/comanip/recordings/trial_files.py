"""Recorded reaches read as trials (times, positions, goal and width): a CSV file, a folder of them, a motion-capture
folder (TAT-HUM's layout, or Vicon Nexus trajectories exports) or a ROS 2 bag. The fit (:mod:`comanip.fitting`) takes
its trials from here.

A recordings file has the columns ``t, x, y`` (and ``z`` for 3-D reaches): t in s from the movement's
start, positions in m. A ``trial`` column names the trial of each row (rows of one trial in time order);
without it the whole file is one trial, named after the file. The first sample of a trial is its start,
where the hand is taken to be at rest. Each trial's goal and width come from columns
``goal_x, goal_y[, goal_z], width`` (m) repeated on its rows, or from a separate trials table with the
columns ``trial, goal_x, goal_y[, goal_z], width``. Times that look like ms or positions that look like mm
(:mod:`comanip.units`) are refused unless ``check_units=False``. A ROS 2 bag
(:mod:`comanip.recordings.ros_bags`) is one trial named after the bag, its goal and width from a trials table,
its positions the first d of x, y, z for the table's d-coordinate goals. See docs/fitting.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from comanip.arguments import as_positive
from comanip.recordings.csv_table import read_table
from comanip.recordings.motion_capture import load_tathum
from comanip.recordings.nexus_trajectories import is_nexus_export, load_nexus_trajectories, nexus_exports
from comanip.recordings.ros_bags import bag_name, bag_samples, is_bag
from comanip.units import check_positions_m, check_times_s

AXES = ("x", "y", "z")
GOAL_COLUMNS = tuple(f"goal_{a}" for a in AXES)


@dataclass(frozen=True)
class Trial:
    """One recorded reach: K samples of the hand in d task dimensions."""

    name: str
    """Trial identifier (the ``trial`` column, or the file name without extension)."""
    t: np.ndarray
    """Sample times (K,), s from the movement's start, strictly increasing, ≥ 0."""
    position: np.ndarray
    """Hand positions (K, d), m."""
    goal: np.ndarray
    """Goal position (d,), m."""
    width: float
    """Goal width w (m)."""

    @property
    def start(self) -> np.ndarray:
        """The first sample (d,), m: where the hand rests before the reach."""
        return self.position[0]


def load_recordings(path: str | Path, trials: str | Path | None = None, *, check_units: bool = True,
                    topic: str | None = None, frame: str | None = None, marker: str | None = None,
                    max_gap: float | None = None) -> list[Trial]:
    """Trials from a recordings CSV or a folder of them (every ``*.csv`` in it, by name), from a ROS 2 bag, or from
    motion capture.

    Args:
        path: a recordings file, a folder of recordings files, a bag (its trial's goal and width from
            ``trials``), a motion-capture folder in the TAT-HUM layout, or a Vicon Nexus trajectories export or a
            folder of them (:mod:`comanip.recordings.nexus_trajectories`); for motion capture, :func:`tracked_trials`
            gives the goals and widths from the endpoints of each target's trials.
        trials: a trials table (trial, goal_x, goal_y[, goal_z], width) for recordings without goal and
            width columns; a file of that name inside the folder is not read as recordings.
        check_units: refuse a trial whose times look like ms or whose positions and goal look like mm
            (:mod:`comanip.units`); False reads them as s and m whatever they look like.
        topic, frame: a bag's hand topic and frame (:func:`comanip.recordings.ros_bags.bag_samples`).
        marker, max_gap: a Nexus export's marker and longest bridged gap
            (:func:`comanip.recordings.nexus_trajectories.read_nexus_trajectories`; None: its defaults).

    Returns:
        The trials, in file order and then in order of first appearance.

    Raises:
        ValueError (one line) for a missing or empty path, missing columns, non-numeric or non-finite
        values, times that do not increase within a trial, a goal or width that changes within a trial,
        a trial without goal and width, the same trial name twice, or (``check_units``) times in ms or
        positions in mm.
    """
    path = Path(path)
    if is_bag(path):
        return [_bag_trial(path, trials, check_units, topic, frame)]
    if topic is not None or frame is not None:
        raise ValueError(f"a topic and a frame choose the samples of a ROS 2 bag; {str(path)!r} is not a bag")
    if is_tathum_folder(path):
        return tracked_trials(load_tathum(path))
    if is_nexus_export(path) or nexus_exports(path):
        return tracked_trials(load_nexus_trajectories(path, marker, max_gap=max_gap, check_units=check_units))
    if marker is not None or max_gap is not None:
        raise ValueError(f"a marker and a longest gap choose the samples of a Nexus export; {str(path)!r} is not one")
    if path.is_dir():
        skip = None if trials is None else Path(trials).resolve()
        files = [f for f in sorted(path.glob("*.csv")) if f.resolve() != skip]
        if not files:
            raise ValueError(f"recordings folder {str(path)!r} holds no .csv files")
    elif path.is_file():
        files = [path]
    else:
        raise ValueError(f"recordings path {str(path)!r} does not exist (give a CSV file or a folder of them)")
    targets = None if trials is None else read_trials_table(trials)
    result: list[Trial] = []
    for file in files:
        result += _trials_in_file(file, targets, check_units)
    names = [trial.name for trial in result]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ValueError(f"recordings: trial names {repeated[:5]} appear in more than one file; name trials uniquely")
    dimensions = {trial.position.shape[1] for trial in result}
    if len(dimensions) > 1:
        raise ValueError(f"recordings mix {sorted(dimensions)}-D trials; every file needs the same position columns")
    return result


def is_tathum_folder(path: Path) -> bool:
    """Whether ``path`` is a motion-capture data folder in the TAT-HUM layout (:mod:`comanip.recordings.motion_capture`)."""
    return path.is_dir() and (path / "trajectory_data").is_dir() and (path / "trial_data").is_dir()


SINGLE_TRIAL_WIDTH_M = 0.01
"""Width (m) of a target with a single trial, whose endpoints have no spread to measure."""


def tracked_trials(samples) -> list[Trial]:
    """Trials for a fit from tracked reaches (:class:`~comanip.recordings.TrackedSamples`) whose goals are not
    recorded, only which target each aimed at (``label["target"]``, per ``label["participant"]``).

    Each trial starts at its onset (:meth:`~comanip.recordings.TrackedSamples.recording`; the first sample is
    the start at rest) and runs to its end, its samples the preprocessed recording's. The
    goal of a (participant, target) group is the mean of its endpoints, and its width the root-mean-square
    over the axes of the endpoints' standard deviation: the goal's standard deviation that the model's
    W = w²·I reads it as (``goal_covariance: std``), as the people's endpoints spread around it
    (:data:`SINGLE_TRIAL_WIDTH_M` for a target with one trial)."""
    recordings = [trial.recording() for trial in samples]
    groups: dict[tuple, list[int]] = {}
    for k, trial in enumerate(samples):
        groups.setdefault((trial.label.get("participant"), trial.label.get("target")), []).append(k)
    result = []
    for members in groups.values():
        ends = np.array([recordings[k].end for k in members])
        goal = ends.mean(axis=0)
        width = float(np.sqrt(np.mean(ends.var(axis=0)))) if len(members) > 1 else SINGLE_TRIAL_WIDTH_M
        for k in members:
            r = recordings[k]
            keep = (r.t >= r.onset - 1e-9) & (r.t <= r.end_time + 1e-9)
            result.append(Trial(r.name, r.t[keep] - r.t[keep][0], r.position[keep], goal, width))
    return result


def read_trials_table(path: str | Path) -> dict[str, tuple[np.ndarray, float]]:
    """{trial name: (goal (d,) m, width m)} from a CSV with columns trial, goal_x, goal_y[, goal_z], width."""
    table = read_table(path, "trials table", ("trial", "goal_x", "goal_y", "width"), GOAL_COLUMNS + ("width",))
    goal = np.column_stack([table[c] for c in GOAL_COLUMNS if c in table])
    names = list(table["trial"])
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ValueError(f"trials table {str(path)!r} lists trials {repeated[:5]} more than once")
    return {name: (goal[k], as_positive(f"width of trial {name!r}", table["width"][k], "m")) for k, name in enumerate(names)}


def _trials_in_file(path: Path, targets: dict | None, check_units: bool = True) -> list[Trial]:
    """The trials of one recordings file; goal and width from its columns or from ``targets``."""
    table = read_table(path, "recordings", ("t", "x", "y"), ("t",) + AXES + GOAL_COLUMNS + ("width",))
    d = 3 if "z" in table else 2
    has_targets = "width" in table
    if has_targets and not all(c in table for c in GOAL_COLUMNS[:d]):
        raise ValueError(f"recordings file {str(path)!r} has a width column but not all of {list(GOAL_COLUMNS[:d])}")
    if not has_targets and targets is None:
        raise ValueError(f"recordings file {str(path)!r} has no goal_x/goal_y/width columns; add them or give a trials table")
    labels = table["trial"] if "trial" in table else np.full(len(table["t"]), path.stem)
    position = np.column_stack([table[a] for a in AXES[:d]])
    trials = []
    for name in dict.fromkeys(labels):
        rows = np.flatnonzero(labels == name)
        where = f"recordings file {str(path)!r}, trial {str(name)!r}"
        if has_targets:
            goal, width = _constant_targets(table, rows, d, where)
        elif name not in targets:
            raise ValueError(f"{where} is not in the trials table")
        else:
            goal, width = targets[name]
        trial = _checked_trial(str(name), table["t"][rows], position[rows], goal, width, where)
        if check_units:
            check_times_s(trial.t, f"{where}, column 't'")
            check_positions_m(np.vstack([trial.position, trial.goal]), f"{where}, columns {list(AXES[:d])} and the goal")
        trials.append(trial)
    return trials


def _bag_trial(path: Path, trials: str | Path | None, check_units: bool, topic: str | None, frame: str | None) -> Trial:
    """The trial in a bag, named after it, its goal and width from the trials table."""
    name = bag_name(path)
    if trials is None:
        raise ValueError(f"bag {str(path)!r} holds no goal and width; give a trials table (trial, goal_x, goal_y[, goal_z], "
                         f"width) with a row for trial {name!r}")
    targets = read_trials_table(trials)
    if name not in targets:
        raise ValueError(f"trials table {str(trials)!r} has no row for trial {name!r} (the bag's name)")
    goal, width = targets[name]
    t, position = bag_samples(path, topic, frame=frame, axes="xyz"[:len(goal)], check_units=check_units)
    where = f"bag {str(path)!r}"
    if check_units:
        check_positions_m(np.vstack([position, goal]), f"{where}, positions and the goal")
    return _checked_trial(name, t, position, goal, width, where)


def _constant_targets(table: dict, rows: np.ndarray, d: int, where: str) -> tuple[np.ndarray, float]:
    goal = np.column_stack([table[c][rows] for c in GOAL_COLUMNS[:d]])
    width = table["width"][rows]
    if np.ptp(goal, axis=0).max() > 0 or np.ptp(width) > 0:
        raise ValueError(f"{where}: the goal or width changes within the trial; each trial has one goal and width")
    return goal[0], width[0]


def _checked_trial(name: str, t: np.ndarray, position: np.ndarray, goal, width, where: str) -> Trial:
    if len(t) < 3:
        raise ValueError(f"{where} has {len(t)} samples; a trial needs at least 3")
    if t[0] < 0:
        raise ValueError(f"{where} starts at t = {t[0]} s; t counts seconds from the movement's start (≥ 0)")
    steps = np.diff(t)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0))
        raise ValueError(f"{where}: t must increase from sample to sample, but goes {t[k]} -> {t[k + 1]} s at sample {k + 1}")
    goal = np.asarray(goal, dtype=float)
    if goal.shape != (position.shape[1],):
        raise ValueError(f"{where}: the goal has {goal.size} coordinates, the positions {position.shape[1]}")
    width = as_positive(f"width of {where}", width, "m")
    return Trial(name, t, position, goal, width)
