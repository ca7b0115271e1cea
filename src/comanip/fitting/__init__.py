"""Fitting a reaching model's parameters to data. The recording format is described in docs/fitting.md."""

from comanip.fitting.recordings import Trial, load_recordings

__all__ = ["Trial", "load_recordings"]
