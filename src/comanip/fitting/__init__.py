"""Fitting a reaching model's parameters to data: recorded hand trajectories (maximum likelihood of their positions,
:func:`fit_model`, or their timing matched by the model's closed-loop reaches, :func:`fit_timing`) or published
movement times per condition (least squares, :func:`fit_movement_times`).
The recording format and the method are described in docs/fitting.md."""

from importlib import import_module

_EXPORTS = {"fit_model": "comanip.fitting.fit", "recordings_nll": "comanip.fitting.fit",
            "fit_movement_times": "comanip.fitting.movement_times", "fit_timing": "comanip.fitting.timing_fit", "MovementTimeTable": "comanip.fitting.movement_times",
            "Trial": "comanip.recordings.trial_files", "load_recordings": "comanip.recordings.trial_files",
            "FitResult": "comanip.fitting.fit_result", "FitStatus": "comanip.fitting.fit_result"}
"""the public names and their modules, imported on first use (the CLI reads DEFAULT_PARAMETERS without scipy)"""

__all__ = ["fit_model", "recordings_nll", "fit_movement_times", "fit_timing", "MovementTimeTable", "Trial", "load_recordings", "FitResult", "FitStatus"]


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'comanip.fitting' has no attribute {name!r}")
    value = getattr(import_module(_EXPORTS[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
