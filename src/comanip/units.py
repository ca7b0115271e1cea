"""Unit checks of recorded data: times that look like milliseconds, positions that look like millimetres,
joint angles that look like degrees.

comanip reads times in s, positions in m and joint angles in rad. A recording in ms or mm loads without
complaint and fits or estimates nonsense, so the loaders call these checks on every trial or observation
file. Each judges one recording of one reach by its span (last minus first sample) and its steps (between
successive samples) against what a reach can be, and raises a one-line ValueError naming the column and the
likely unit. Pure functions over arrays; a loader's ``check_units=False`` (the CLI's ``--skip-unit-check``)
skips them for data that really is unusual.
"""

from __future__ import annotations

import numpy as np

MAX_REACH_DURATION_S = 60.0
"""Longest recording of one reach (s): a longer span suggests milliseconds (a 1 s reach spans 1000 in ms)."""
MAX_SAMPLE_STEP_S = 0.5
"""Longest typical step between samples (s): a hand sampled below 2 Hz is not a reach recording; steps of
1 to 20 (a 1 kHz to 50 Hz recording in ms) are caught here even in short recordings."""
MAX_REACH_SPAN_M = 3.0
"""Largest extent of one reach's hand positions along an axis (m): more than arm span and a step; a 300 mm
reach recorded in mm spans 300."""
MAX_ANGLE_RAD = 2 * np.pi
"""Largest joint angle magnitude (rad); a joint at 30° recorded in degrees reads 30."""

SKIP_HINT = "if the units are right, skip this check (check_units=False; on the command line --skip-unit-check)"


def check_times_s(t, where: str) -> np.ndarray:
    """Times t (K,) as floats when they look like seconds, else ValueError naming ``where`` (e.g. "recordings
    file 'a.csv', column 't'") and the likely unit: a span over MAX_REACH_DURATION_S or a median step over
    MAX_SAMPLE_STEP_S reads as milliseconds."""
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return t
    span = float(np.max(t) - np.min(t))
    step = float(np.median(np.abs(np.diff(t))))
    if span > MAX_REACH_DURATION_S or step > MAX_SAMPLE_STEP_S:
        raise ValueError(f"{where}: times span {span:g} with median step {step:g}, too long for one reach in s "
                         f"(at most {MAX_REACH_DURATION_S:g} s and steps of {MAX_SAMPLE_STEP_S:g} s); they look like "
                         f"milliseconds: divide by 1000 ({SKIP_HINT})")
    return t


def check_positions_m(x, where: str) -> np.ndarray:
    """Positions x (K,) or (K, d) as floats when they look like metres, else ValueError naming ``where`` and
    the likely unit: an extent over MAX_REACH_SPAN_M along any axis reads as millimetres."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return x
    span = float(np.max(np.ptp(x.reshape(len(x), -1), axis=0)))
    if span > MAX_REACH_SPAN_M:
        raise ValueError(f"{where}: positions span {span:g} along an axis, more than one reach's {MAX_REACH_SPAN_M:g} m; "
                         f"they look like millimetres: divide by 1000 ({SKIP_HINT})")
    return x


def check_angles_rad(q, where: str) -> np.ndarray:
    """Joint angles q (K,) or (K, n) as floats when they look like radians, else ValueError naming ``where``:
    a magnitude over MAX_ANGLE_RAD reads as degrees."""
    q = np.asarray(q, dtype=float)
    largest = float(np.max(np.abs(q))) if q.size else 0.0
    if largest > MAX_ANGLE_RAD:
        raise ValueError(f"{where}: a joint angle of {largest:g}, beyond ±2π rad; the angles look like degrees: "
                         f"multiply by π/180 ({SKIP_HINT})")
    return q
