"""Fitting a reaching model's parameters to data: recorded hand trajectories (maximum likelihood,
:func:`fit_model`) or published movement times per condition (least squares, :func:`fit_movement_times`).
The recording format and the method are described in docs/fitting.md."""

from comanip.fitting.fit import fit_model, recordings_nll
from comanip.fitting.movement_times import MovementTimeTable, fit_movement_times
from comanip.fitting.recordings import Trial, load_recordings
from comanip.fitting.result import FitResult

__all__ = ["fit_model", "recordings_nll", "fit_movement_times", "MovementTimeTable", "Trial", "load_recordings", "FitResult"]
