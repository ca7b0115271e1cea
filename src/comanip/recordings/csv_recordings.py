"""Recordings read from the project's recordings CSV (docs/data_formats.md), preprocessed as
:mod:`comanip.recordings.preprocessing` describes; each trial's goal becomes the recording's ``target``."""

from __future__ import annotations

from pathlib import Path

from comanip.recordings.preprocessing import STEP, recording_from_samples
from comanip.recordings.recording import Recording
from comanip.recordings.trial_files import load_recordings


def load_csv_recordings(path: str | Path, trials: str | Path | None = None, *, step: float = STEP) -> list[Recording]:
    """Recordings of the trials in a recordings CSV or a folder of them (:func:`~comanip.recordings.trial_files.load_recordings`:
    its columns, checks and errors), resampled onto a grid of ``step`` s with their onset and end."""
    return [recording_from_samples(trial.name, trial.t, trial.position, step=step, width=trial.width, target=trial.goal)
            for trial in load_recordings(path, trials)]
