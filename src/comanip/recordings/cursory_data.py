"""The ``cursory`` package's recorded mouse movements as :class:`~comanip.recordings.recording.Recording` s.

``cursory`` (PyPI, LGPL-3.0; ``pip install -e ".[data]"``) ships ``trajectories.json.gz``: 2,356 screen-mouse
movements recorded from people, each with its ``start`` and ``end`` (px), the cursor's ``points`` (px) and
their ``timing`` (ms). comanip reads the file only (it does not import the package) and maps pixels to metres
by ``scale`` (the default makes the median movement 0.33 m, an arm's reach on a table; times stay as
recorded). The movements whose index in the file is a multiple of 5 form the **held-out split**: fit, tune
and select on the development split (the rest), and report on the held-out split.
"""

from __future__ import annotations

import gzip
import importlib.util
import json
from pathlib import Path

import numpy as np

from comanip.arguments import as_positive
from comanip.recordings.preprocessing import STEP, recording_from_samples
from comanip.recordings.recording import Recording

SCALE = 0.0005
"""Default mapping from pixels to metres (m/px)."""
SPLITS = ("development", "held_out", "all")
"""Names of the splits :func:`load_cursory` takes."""
HELD_OUT_EVERY = 5
"""Movements whose index in the file is a multiple of this are held out."""


def cursory_file() -> Path:
    """Path of ``trajectories.json.gz`` in the installed ``cursory`` package (ValueError when not installed)."""
    spec = importlib.util.find_spec("cursory")
    if spec is None or not spec.submodule_search_locations:
        raise ValueError("the 'cursory' package is not installed; install the data extra: pip install -e \".[data]\"")
    path = Path(next(iter(spec.submodule_search_locations))) / "trajectories.json.gz"
    if not path.is_file():
        raise ValueError(f"the installed 'cursory' package has no trajectories file at {str(path)!r}")
    return path


def split_indices(count: int, split: str) -> np.ndarray:
    """Indices (into the file's list) of the movements in ``split`` (one of :data:`SPLITS`)."""
    if split not in SPLITS:
        raise ValueError(f"split must be one of {SPLITS}, got {split!r}")
    index = np.arange(count)
    held_out = index % HELD_OUT_EVERY == 0
    return index if split == "all" else index[held_out if split == "held_out" else ~held_out]


def load_cursory(split: str = "development", *, scale: float = SCALE, step: float = STEP, limit: int | None = None,
                 path: str | Path | None = None) -> list[Recording]:
    """Recordings of the ``cursory`` movements in ``split`` (module docstring), in file order.

    Args:
        split: "development", "held_out" or "all".
        scale: pixels to metres (m/px).
        step: resampling step (s) (:mod:`comanip.recordings.preprocessing`).
        limit: at most this many movements (the first of the split); None: all.
        path: a trajectories file of the same format; None: the installed package's.

    Movements that never move are left out. Each recording's ``target`` is the file's ``end``.
    """
    scale = as_positive("scale", scale, "m/px")
    with gzip.open(cursory_file() if path is None else path, "rt", encoding="utf-8") as stream:
        movements = json.load(stream)
    indices = split_indices(len(movements), split)
    if limit is not None:
        indices = indices[:limit]
    recordings = []
    for k in indices:
        movement = movements[k]
        points = scale * np.asarray(movement["points"], dtype=float)
        times = 1e-3 * np.asarray(movement["timing"], dtype=float)
        if len(points) < 3 or np.ptp(points, axis=0).max() == 0:
            continue
        recordings.append(recording_from_samples(f"cursory/{k}", times, points, step=step,
                                                 target=scale * np.asarray(movement["end"], dtype=float)))
    return recordings
