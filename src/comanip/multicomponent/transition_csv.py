"""The transition-data CSV: one row per reaching condition (goal distance, goal width).

Columns (the first three are required; a lab's own measurements need only those):

| column | meaning |
|---|---|
| distance_over_arm_length | goal distance D divided by the arm length L (dimensionless) |
| width_m | goal width w, m |
| transition_distance_m | distance from the goal of the peak perpendicular dispersion, m |
| peak_dispersion_m | the peak perpendicular dispersion, m (optional) |
| n_trials | trials behind the row (optional) |
| transition_distance_se_m | bootstrap standard error of transition_distance_m, m (optional) |
| settled_trials | trials that ended at rest inside the goal (optional) |
| failed_replans | replans that did not converge, summed over the trials (optional) |

A JSON file beside the CSV (same name, ``.json``) holds how the data were made (command, seed, model).
"""

from __future__ import annotations

import csv
import json
import math
from importlib import resources
from pathlib import Path

import numpy as np

REQUIRED_COLUMNS = ("distance_over_arm_length", "width_m", "transition_distance_m")
OPTIONAL_COLUMNS = ("peak_dispersion_m", "n_trials", "transition_distance_se_m", "settled_trials", "failed_replans")
COLUMNS = REQUIRED_COLUMNS + OPTIONAL_COLUMNS


def shipped_dataset_path() -> Path:
    """The default dataset shipped in the package (planar preset; see comanip/data/README.md)."""
    return Path(str(resources.files("comanip") / "data" / "transition_planar.csv"))


def write_transition_csv(rows: list[dict], path: str | Path, metadata: dict | None = None) -> Path:
    """Write rows (dicts keyed by :data:`COLUMNS`) to path, and metadata to the JSON file beside it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(COLUMNS), extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: _format(row.get(k, "")) for k in COLUMNS})
    if metadata is not None:
        path.with_suffix(".json").write_text(json.dumps(metadata, indent=1))
    return path


def read_transition_metadata(path: str | Path) -> dict | None:
    """The JSON written beside a transition CSV by :func:`write_transition_csv` (command, seed, model, ...), or
    None when there is none (e.g. a lab's own CSV)."""
    metadata = Path(path).with_suffix(".json")
    return json.loads(metadata.read_text()) if metadata.is_file() else None


def read_transition_csv(path: str | Path) -> dict[str, np.ndarray]:
    """Columns of a transition CSV as float arrays (N,), checked by :func:`check_transition_columns`."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"transition data file {str(path)!r} does not exist (expected a CSV with columns {list(REQUIRED_COLUMNS)})")
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        header = reader.fieldnames or []
        missing = [c for c in REQUIRED_COLUMNS if c not in header]
        if missing:
            raise ValueError(f"{path} lacks the column(s) {missing}; a transition CSV needs {list(REQUIRED_COLUMNS)} "
                             f"(optional: {list(OPTIONAL_COLUMNS)}), found {header}")
        records = list(reader)
    columns = {}
    for name in (c for c in COLUMNS if c in header):
        values = [r[name] for r in records]
        if name in OPTIONAL_COLUMNS and all(v in ("", None) for v in values):
            continue
        try:
            columns[name] = np.array([float(v) if v not in ("", None) else math.nan for v in values])
        except ValueError as error:
            raise ValueError(f"{path}: column {name!r} must hold numbers: {error}") from None
    return check_transition_columns(columns, source=str(path))


def check_transition_columns(columns: dict, source: str = "data") -> dict[str, np.ndarray]:
    """Validated float arrays (N,) of the required columns (and any optional ones), else ValueError.

    D/L > 0, w > 0 (m), transition distance ≥ 0 (m), all finite, columns of equal length.
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in columns]
    if missing:
        raise ValueError(f"{source} lacks {missing}; needs {list(REQUIRED_COLUMNS)}")
    out = {name: np.atleast_1d(np.asarray(columns[name], dtype=float)) for name in COLUMNS if name in columns}
    lengths = {name: len(v) for name, v in out.items()}
    if len(set(lengths.values())) != 1:
        raise ValueError(f"{source}: columns must have equal lengths, got {lengths}")
    for name in REQUIRED_COLUMNS:
        bad = np.flatnonzero(~np.isfinite(out[name]))
        if bad.size:
            raise ValueError(f"{source}: column {name!r} holds NaN or inf at row(s) {bad[:5].tolist()}; every value must be a finite number")
    _check_sign(out, "distance_over_arm_length", source, "> 0 (goal distance / arm length)", lambda v: v > 0)
    _check_sign(out, "width_m", source, "> 0 (goal width, m)", lambda v: v > 0)
    _check_sign(out, "transition_distance_m", source, "≥ 0 (distance from the goal, m)", lambda v: v >= 0)
    return out


def _check_sign(columns, name, source, allowed, ok):
    bad = np.flatnonzero(~ok(columns[name]))
    if bad.size:
        raise ValueError(f"{source}: column {name!r} must be {allowed}; row {int(bad[0])} holds {columns[name][bad[0]]!r}")


def _format(value):
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    return value
