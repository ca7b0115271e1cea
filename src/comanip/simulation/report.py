"""Writing a scenario's results: one CSV per trial, a summary JSON, the figure and a frame strip."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, fields, is_dataclass
from pathlib import Path

import numpy as np

from comanip.simulation.scenario import ScenarioSettings, TrialRecord


def summarise(metrics: list[dict]) -> dict:
    """Mean, std (ddof 1 when ≥ 2 trials), median, quartiles (q25, q75), min and max over the trials where
    each numeric scalar measure is finite; booleans give the fraction of trials where they hold."""
    out = {}
    for key in metrics[0]:
        values = [m[key] for m in metrics]
        if all(isinstance(v, (bool, np.bool_)) for v in values):
            out[key] = {"fraction": float(np.mean(values))}
        elif all(isinstance(v, (int, float, np.integer, np.floating)) for v in values):
            array = np.asarray(values, dtype=float)
            finite = array[np.isfinite(array)]
            out[key] = {"mean": _number(np.mean(finite)) if len(finite) else None,
                        "std": _number(np.std(finite, ddof=1)) if len(finite) > 1 else None,
                        "median": _number(np.median(finite)) if len(finite) else None,
                        "q25": _number(np.percentile(finite, 25)) if len(finite) else None,
                        "q75": _number(np.percentile(finite, 75)) if len(finite) else None,
                        "min": _number(np.min(finite)) if len(finite) else None,
                        "max": _number(np.max(finite)) if len(finite) else None,
                        "finite_trials": int(len(finite))}
    return out


def settings_dict(settings: ScenarioSettings) -> dict:
    """The settings as JSON-ready data (nested dataclasses included)."""
    return {f.name: (asdict(getattr(settings, f.name)) if is_dataclass(getattr(settings, f.name)) else getattr(settings, f.name))
            for f in fields(settings)}


def write_trials(records: list[TrialRecord], out: Path, stem: str) -> list[Path]:
    """One CSV per trial, ``{stem}_trial{k}.csv``."""
    paths = []
    for k, record in enumerate(records):
        path = out / f"{stem}_trial{k}.csv"
        record.save_csv(path)
        paths.append(path)
    return paths


def write_summary(path: Path, content: dict) -> Path:
    """The summary as indented JSON, NaN written as null."""
    path.write_text(json.dumps(_clean(content), indent=1))
    return path


def _number(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _clean(value):
    """JSON-ready copy: arrays to lists, non-finite floats to None."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, np.ndarray):
        return _clean(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return _number(value)
    if isinstance(value, Path):
        return str(value)
    return value
