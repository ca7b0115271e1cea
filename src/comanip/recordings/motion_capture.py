"""Hand positions from a motion-capture tracker: raw samples with the gaps a tracker leaves, and their loaders.

A tracker (Optotrak, Vicon, OptiTrack, a camera hand tracker) reports a marker's position at a fixed rate and
loses it now and then. Here a lost sample is a gap, never a position: a row of NaN (or, as some systems
write it, x = y = z = 0 exactly) is kept in :class:`TrackedSamples` as NaN, and every consumer skips it.

Two formats are read:

- **A tracker CSV** (:func:`read_tracker_csv`): a header row ``t, x, y, z`` (t in s, positions in m; a 2-D
  tracker has ``t, x, y``), one row per sample, an empty cell or ``nan`` where the marker was lost.
- **The TAT-HUM layout** (:func:`load_tathum`), as the TAT-HUM toolbox's 3-D demo data lays out an
  experiment: ``trajectory_data/parP/parP_trial_N.csv`` without a header, columns time (s), frame, x, y, z
  (mm), one file per trial (an empty file: the trial was not recorded), and ``trial_data/parP_tathum.csv``,
  the experiment's log (PsychoPy) with one row per trial: ``trials.thisN`` (the N of the file name),
  ``target``, ``soa`` (ms), ``keep_trial`` (False: the experimenter rejected it) and ``trials.thisRepN`` (the
  block; block 0 is practice). Any number of participants ``parP``.

:meth:`TrackedSamples.recording` turns samples into a preprocessed
:class:`~comanip.recordings.recording.Recording` (the gaps bridged by interpolation), and
:meth:`TrackedSamples.stream` replays them as a live tracker delivers them to an online estimator.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from comanip.arguments import as_positive
from comanip.recordings.preprocessing import recording_from_samples
from comanip.recordings.recording import Recording
from comanip.units import check_positions_m, check_times_s

TRACKER_AXES = ("x", "y", "z")
"""Position columns of a tracker CSV (the first two for a 2-D tracker)."""
STREAM_RATE_HZ = 125.0
"""Default rate (Hz) at which :meth:`TrackedSamples.stream` delivers samples."""
VELOCITY_WINDOW_S = 0.024
"""Default span (s) of the backward difference that gives a streamed sample's velocity."""
RECORDING_STEP_S = 0.004
"""Resampling step (s) of :meth:`TrackedSamples.recording` (a 250 Hz tracker's own)."""
STREAM_LEAD_S = 0.15
"""Default time (s) before the onset from which :meth:`TrackedSamples.streamed_recording` streams (hand at rest)."""
BRIDGED_GAP_S = 10.0
"""Gaps up to this long (s) are bridged by interpolation in :meth:`TrackedSamples.recording` (every gap of a
reach: a lost marker kept moving, unlike a mouse that sends nothing while it is still)."""


@dataclass(frozen=True)
class TrackedSamples:
    """Raw samples of one tracked marker: K samples in d dimensions, lost samples NaN."""

    name: str
    """Identifier of the trial."""
    t: np.ndarray
    """Sample times (K,), s, strictly increasing."""
    position: np.ndarray
    """Marker positions (K, d), m; a row of NaN where the tracker lost the marker."""
    label: dict
    """What the trial's log says of it (e.g. ``{"participant": "par1", "trial": 12, "target": 2, "soa_ms": 100}``)."""

    @property
    def tracked(self) -> np.ndarray:
        """(K,) bool: True where the marker was seen."""
        return np.all(np.isfinite(self.position), axis=1)

    @property
    def first_tracked(self) -> float:
        """Time (s on ``t``) of the first tracked sample: time 0 of :meth:`recording` and :meth:`stream`."""
        return float(self.t[np.argmax(self.tracked)])

    def recording(self, *, step: float = RECORDING_STEP_S, **preprocessing) -> Recording:
        """The trial as a :class:`Recording`, its times counted from :attr:`first_tracked`: the tracked samples
        resampled every ``step`` s (gaps bridged linearly), smoothed, its onset and end found (:func:`~comanip.recordings.preprocessing.recording_from_samples`,
        whose keyword arguments ``preprocessing`` passes on)."""
        seen = self.tracked
        if seen.sum() < 3:
            raise ValueError(f"trial {self.name!r} has {int(seen.sum())} tracked samples; a recording needs at least 3")
        preprocessing.setdefault("hold_gap", BRIDGED_GAP_S)   # a lost marker kept moving: interpolate, do not hold
        return recording_from_samples(self.name, self.t[seen] - self.first_tracked, self.position[seen], step=step,
                                      **preprocessing)

    def stream(self, *, rate_hz: float = STREAM_RATE_HZ, velocity_window: float = VELOCITY_WINDOW_S,
               start: float | None = None, stop: float | None = None):
        """The samples as a live tracker delivers them: times (M,) s since ``start``, positions (M, d) m as
        recorded and velocities (M, d) m/s by a backward difference over at least ``velocity_window`` s (the
        newest tracked sample minus the one that window earlier), at about ``rate_hz`` (every k-th sample, k
        the nearest whole ratio of the tracker's rate). A lost sample is delivered as NaN (position and
        velocity), as the tracker would; so is a velocity whose window holds no tracked sample.

        Args:
            start: first time delivered (s since :attr:`first_tracked`, the time base of :meth:`recording`, so
                ``recording.onset - 0.15`` starts 0.15 s before the onset; None: the first sample); the
                times returned count from it.
            stop: last time delivered (s since :attr:`first_tracked`; None: the last sample).
        """
        rate_hz = as_positive("rate_hz", rate_hz, "Hz")
        velocity_window = as_positive("velocity_window", velocity_window, "s")
        t, position = self.t - self.first_tracked, self.position
        tracker_step = float(np.median(np.diff(t)))
        every = max(1, int(round(1.0 / (rate_hz * tracker_step))))
        begin = t[0] if start is None else start
        end = t[-1] if stop is None else stop
        chosen = np.flatnonzero((t >= begin - 1e-9) & (t <= end + 1e-9))[::every]
        seen = np.flatnonzero(self.tracked)
        # for each chosen sample, the newest tracked sample at least the window earlier (-1: none)
        earlier = np.searchsorted(t[seen], t[chosen] - velocity_window + 1e-9, side="right") - 1
        velocity = np.full((len(chosen), position.shape[1]), np.nan)
        ok = self.tracked[chosen] & (earlier >= 0)
        j = seen[earlier[ok]]
        velocity[ok] = (position[chosen[ok]] - position[j]) / (t[chosen[ok]] - t[j])[:, None]
        return np.maximum(t[chosen] - begin, 0.0), position[chosen].copy(), velocity   # a chosen time may lie 1e-9 s early

    def streamed_recording(self, *, lead: float = STREAM_LEAD_S, rate_hz: float = STREAM_RATE_HZ,
                           velocity_window: float = VELOCITY_WINDOW_S) -> Recording:
        """The trial as a live tracker streams it, as a :class:`Recording`: from ``lead`` s before its onset to its
        end, the samples of :meth:`stream` (raw positions, backward-difference velocities; lost samples left
        out), with the onset and end of the preprocessed :meth:`recording`, on the stream's clock (time 0 at
        the first sample streamed). What an online estimator sees, and what a model of people fitted to feed
        one should see."""
        recording = self.recording()
        begin = max(recording.onset - as_positive("lead", lead, "s"), 0.0)
        t, position, velocity = self.stream(start=begin, stop=recording.end_time, rate_hz=rate_hz,
                                            velocity_window=velocity_window)
        seen = np.all(np.isfinite(position), axis=1) & np.all(np.isfinite(velocity), axis=1)
        return Recording(name=self.name, t=t[seen], position=position[seen], velocity=velocity[seen],
                         onset=recording.onset - begin, end_time=recording.end_time - begin)


def _gaps_as_nan(position: np.ndarray) -> np.ndarray:
    """Positions with the rows a tracker writes for a lost marker (all exactly 0, or any NaN) set to NaN."""
    position = np.array(position, dtype=float)
    lost = np.all(position == 0.0, axis=1) | ~np.all(np.isfinite(position), axis=1)
    position[lost] = np.nan
    return position


def _checked(name: str, t: np.ndarray, position: np.ndarray, where: str, check_units: bool) -> TrackedSamples:
    """TrackedSamples after the checks every loader makes: increasing finite times, s and m units."""
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{where}: a time is missing or not a finite number; every row needs its time in s")
    if np.any(np.diff(t) <= 0):
        sample = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 2
        raise ValueError(f"{where}: times must increase from sample to sample, sample {sample} (counting from 1, "
                         f"without a header) does not ({t[sample - 2]:g} then {t[sample - 1]:g} s)")
    if check_units:
        check_times_s(t, f"{where}, times")
        seen = np.all(np.isfinite(position), axis=1)
        check_positions_m(position[seen], f"{where}, positions")
    return TrackedSamples(name, t, position, {})


def read_tracker_csv(path: str | Path, *, check_units: bool = True) -> TrackedSamples:
    """Samples of a tracker CSV (module docstring): header ``t, x, y[, z]``, times in s, positions in m, an empty
    cell or ``nan`` for a lost sample. A one-line ValueError for a missing column, a time that is not a number
    or does not increase, and (``check_units``) times that look like ms or positions that look like mm."""
    path = Path(path)
    with open(path, newline="") as stream:
        reader = csv.DictReader(stream)
        header = [c.strip() for c in (reader.fieldnames or [])]
        axes = [a for a in TRACKER_AXES if a in header]
        if "t" not in header or axes not in (["x", "y"], ["x", "y", "z"]):
            raise ValueError(f"tracker CSV {str(path)!r} needs the columns t, x, y[, z] (s, m); its header is {header}")
        rows = [{k.strip(): v for k, v in row.items() if k is not None} for row in reader]
    if not rows:
        raise ValueError(f"tracker CSV {str(path)!r} has no rows")

    def number(text, column, row):
        text = (text or "").strip()
        if text == "" and column != "t":
            return math.nan
        try:
            return float(text)
        except ValueError:
            raise ValueError(f"tracker CSV {str(path)!r}, row {row}, column {column!r}: {text!r} is not a number") from None

    t = np.array([number(r.get("t"), "t", k + 2) for k, r in enumerate(rows)])
    position = np.array([[number(r.get(a), a, k + 2) for a in axes] for k, r in enumerate(rows)])
    samples = _checked(path.stem, t, _gaps_as_nan(position), f"tracker CSV {str(path)!r}", check_units)
    return TrackedSamples(samples.name, samples.t, samples.position, {"file": str(path)})


_TRIAL_FILE = re.compile(r"^(?P<participant>.+)_trial_(?P<trial>\d+)\.csv$")


def load_tathum(folder: str | Path, *, participants=None, include_rejected: bool = False,
                include_practice: bool = False) -> list[TrackedSamples]:
    """The trials of a TAT-HUM 3-D data folder (module docstring), positions in m (the files' mm / 1000).

    Args:
        folder: the folder that holds ``trajectory_data/`` and ``trial_data/`` (TAT-HUM's ``data_3d``).
        participants: names of the participants to read (e.g. ``["par1"]``); None: every ``parP`` folder.
        include_rejected: also the trials the log marks ``keep_trial`` False.
        include_practice: also the trials of block 0 (practice).

    Returns:
        One :class:`TrackedSamples` per recorded trial, by participant and trial number, named
        ``"parP/N"``, with ``label`` {participant, trial, target, soa_ms, block}. Empty trial files (trials
        that were not recorded) and trials without a row in the log are left out.
    """
    folder = Path(folder)
    trajectories, logs = folder / "trajectory_data", folder / "trial_data"
    if not trajectories.is_dir() or not logs.is_dir():
        raise ValueError(f"{str(folder)!r} is not a TAT-HUM data folder: it needs trajectory_data/ and trial_data/ inside")
    names = sorted(p.name for p in trajectories.iterdir() if p.is_dir()) if participants is None else list(participants)
    trials = []
    for participant in names:
        log = _trial_log(logs / f"{participant}_tathum.csv")
        files = []
        for path in (trajectories / participant).glob("*.csv"):
            match = _TRIAL_FILE.match(path.name)
            if match and match["participant"] == participant:
                files.append((int(match["trial"]), path))
        if not files:
            raise ValueError(f"{str(trajectories / participant)!r} holds no {participant}_trial_N.csv files")
        for number, path in sorted(files):
            row = log.get(number)
            if row is None or path.stat().st_size == 0:
                continue
            if (not include_rejected and not row["keep"]) or (not include_practice and row["block"] == 0):
                continue
            data = np.loadtxt(path, delimiter=",", ndmin=2)
            if data.shape[1] != 5:
                raise ValueError(f"{str(path)!r}: a TAT-HUM trajectory has 5 columns (time s, frame, x, y, z mm), got {data.shape[1]}")
            samples = _checked(f"{participant}/{number}", data[:, 0], _gaps_as_nan(data[:, 2:5]) / 1000.0,
                               f"trial file {str(path)!r}", True)
            trials.append(TrackedSamples(samples.name, samples.t, samples.position,
                                         {"participant": participant, "trial": number, "target": row["target"],
                                          "soa_ms": row["soa_ms"], "block": row["block"]}))
    return trials


def _trial_log(path: Path) -> dict[int, dict]:
    """{trial number: {target, soa_ms, keep, block}} from a TAT-HUM trial log; rows without a trial number
    (calibration, instructions) are skipped."""
    if not path.is_file():
        raise ValueError(f"the trial log {str(path)!r} is missing")
    with open(path, newline="") as stream:
        rows = list(csv.DictReader(stream))
    needed = ("trials.thisN", "target", "soa", "keep_trial", "trials.thisRepN")
    missing = [c for c in needed if rows and c not in rows[0]]
    if not rows or missing:
        raise ValueError(f"the trial log {str(path)!r} lacks the columns {missing or list(needed)}")
    log = {}
    for row in rows:
        if not row["trials.thisN"].strip():
            continue
        log[int(float(row["trials.thisN"]))] = {
            "target": int(float(row["target"])) if row["target"].strip() else None,
            "soa_ms": float(row["soa"]) if row["soa"].strip() else None,
            "keep": row["keep_trial"].strip() != "False",
            "block": int(float(row["trials.thisRepN"])) if row["trials.thisRepN"].strip() else None,
        }
    return log
