"""Observation files: timestamped states of a reach in a CSV with the header ``t_s, q0.., qdot0..`` (the columns
of a plan CSV, docs/data_formats.md), read into times and states with every value checked, as ``comanip
estimate --observations`` and the ROS node's replay read them."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from comanip.units import check_angles_rad, check_positions_m, check_times_s


def read_observations(path: str | Path, n: int, *, check_units: bool = True, joint_angles: bool = False,
                      name: str = "observations") -> tuple[np.ndarray, np.ndarray]:
    """Times (K,) s and states (K, 2n) from a CSV with columns t_s, q0..q{n-1}, qdot0..qdot{n-1}, sorted by time.

    A missing column, a value that is not a finite number or a file without rows is a one-line ValueError that
    begins with ``name`` (the option that gave the file, on a command line). ``check_units`` refuses times that
    look like ms and positions q that look like mm, or like degrees when ``joint_angles`` (an arm's q in rad)
    (:mod:`comanip.units`)."""
    columns = ["t_s"] + [f"q{k}" for k in range(n)] + [f"qdot{k}" for k in range(n)]
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in columns if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{name} needs the columns {columns}; {str(path)!r} lacks {missing}")
        try:
            rows = np.array([[float(row[c]) for c in columns] for row in reader])
        except (TypeError, ValueError) as error:
            raise ValueError(f"{name}: a value in {str(path)!r} is missing or not a number ({error})") from None
    if rows.size == 0:
        raise ValueError(f"{name} file {str(path)!r} has no rows")
    if not np.all(np.isfinite(rows)):
        raise ValueError(f"{name} file {str(path)!r} holds NaN or inf; every value must be a finite number")
    rows = rows[np.argsort(rows[:, 0], kind="stable")]
    if check_units:
        where = f"{name} file {str(path)!r}"
        check_times_s(rows[:, 0], f"{where}, column 't_s'")
        positions = rows[:, 1: n + 1]
        if joint_angles:
            check_angles_rad(positions, f"{where}, columns q0..q{n - 1}")
        else:
            check_positions_m(positions, f"{where}, columns q0..q{n - 1}")
    return rows[:, 0], rows[:, 1:]
