"""Vicon Nexus "Trajectories" exports: one marker of a CSV read as :class:`~comanip.recordings.motion_capture.TrackedSamples`,
and a folder of people's trials read as a lab lays them out.

The export, as Nexus writes it (any markers, any rate, any subjects):

1. ``Trajectories`` (the section's name; a byte-order mark before it is ignored);
2. the frame rate, Hz;
3. the marker names, ``Subject:Marker`` (or ``Marker`` without a subject), each over its X, Y, Z columns
   (the name in the X column, two empty cells after it);
4. ``Frame,Sub Frame,X,Y,Z,X,Y,Z,...``;
5. the units of every column (``mm``, ``cm`` or ``m``);

then one row a frame, ``frame, sub frame, x, y, z, ...``; a marker the cameras lost is an empty cell. The section
ends at the first empty row (Nexus may write another section after it). Times are the frame numbers over the
rate, from the first frame; positions are converted to m by the units of line 5.

A trial is one reach from rest to rest, but an export may also hold the start of the next movement (the hand
going back) or a twitch before the reach: :func:`the_reach` keeps the movement that holds the peak speed, from the
end of the movement before it to the start of the one after it (a movement: the speed above 5 % of the peak; it
ends where the speed stays below that for :data:`REST_S`), so that the recording's onset and end are the reach's.

A lost marker is a gap: its frames are NaN in :class:`TrackedSamples`, which
:meth:`~comanip.recordings.motion_capture.TrackedSamples.recording` bridges by linear interpolation (then
resamples, smooths with the package's Savitzky–Golay filter for the velocities and finds the reach's onset and
end at 5 % of its peak speed, :mod:`comanip.recordings.preprocessing`). A gap inside the tracked frames longer
than ``max_gap`` s is refused: interpolating it would invent the reach. Frames lost before the first or after
the last tracked frame are outside the recording and not gaps.

**A folder of people** (:func:`load_nexus_trajectories` on a folder): every export in it or in its
sub-folders (one per person), each one trial. A file named ``<person><task><arm><trial>.csv`` (e.g.
``ADL001FR1.csv``: person ``ADL001``, task ``F``, arm ``R``, trial 1; the task one capital letter, the arm ``R`` or
``L``) is labelled so; another file's person is its folder's name. The marker may name the arm as ``{arm}``:
the default, :data:`FINGERTIP` (``{arm}FTP``), reads the fingertip of the arm that reached.
"""

from __future__ import annotations

import csv
import math
import re
import warnings
from pathlib import Path

import numpy as np

from comanip.arguments import as_positive
from comanip.recordings.motion_capture import TrackedSamples, _checked, _gaps_as_nan
from comanip.recordings.preprocessing import ONSET_FRACTION
from comanip.units import check_positions_m

SECTION = "Trajectories"
"""The first line of a Nexus trajectories export."""
UNITS_M = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}
"""The position units an export may state (line 5), in m."""
MAX_GAP_S = 0.05
"""Default longest gap (s) inside a marker's tracked frames that is bridged by interpolation (5 frames at 100 Hz)."""
REST_S = 0.1
"""How long (s) the speed stays below the onset threshold for a movement to have ended (the time a person's hand
rests between the sub-movements of one reach only rarely exceeds)."""
FINGERTIP = "{arm}FTP"
"""Default marker of a trial: the fingertip of the arm that reached (``RFTP`` or ``LFTP``)."""

_TRIAL_NAME = re.compile(r"^(?P<person>.+?)(?P<task>[A-Z])(?P<arm>[RL])(?P<trial>\d+)$")


def is_nexus_export(path: str | Path) -> bool:
    """Whether ``path`` is a file whose first line is ``Trajectories`` (a Nexus trajectories export)."""
    path = Path(path)
    if not path.is_file():
        return False
    with open(path, encoding="utf-8-sig", errors="replace") as stream:
        first = stream.readline()
    return first.split(",")[0].strip() == SECTION


def nexus_exports(folder: str | Path) -> list[Path]:
    """The Nexus exports in ``folder`` and its sub-folders (one level), sorted by path; [] for a non-folder."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    return [p for p in sorted([*folder.glob("*.csv"), *folder.glob("*/*.csv")]) if is_nexus_export(p)]


def trial_label(path: str | Path) -> dict:
    """What a trial's file name says of it (module docstring): ``{"participant", "task", "arm", "trial", "target"}``,
    the target the person's reach of that task with that arm (``"FR"``); a name of another form gives its folder's
    name as the participant and the file's stem as the target, task, arm and trial None."""
    path = Path(path)
    match = _TRIAL_NAME.match(path.stem)
    if match is None:
        return {"participant": path.parent.name, "task": None, "arm": None, "trial": None, "target": path.stem}
    return {"participant": match["person"], "task": match["task"], "arm": match["arm"], "trial": int(match["trial"]),
            "target": match["task"] + match["arm"]}


def read_nexus_trajectories(path: str | Path, marker: str | None = None, *, max_gap: float | None = None,
                            check_units: bool = True) -> TrackedSamples:
    """One marker of a Nexus trajectories export (module docstring) as tracked samples: times (K,) s from the first
    frame, positions (K, 3) m, NaN where the marker was lost.

    Args:
        path: the export (CSV).
        marker: the marker's name, with or without its subject (``RFTP`` or ``ADL001:RFTP``); ``{arm}`` in it is
            the arm of the file's name (``R`` in ``ADL001FR1.csv``); None: :data:`FINGERTIP`.
        max_gap: the longest gap (s) inside the marker's tracked frames that is accepted (bridged later by
            interpolation); a longer one is refused. None: :data:`MAX_GAP_S`.
        check_units: warn when the positions, in m by the stated units, span more than a reach can (the units
            line is likely wrong).

    Returns:
        :class:`TrackedSamples` named after the file's stem, its ``label`` :func:`trial_label` with the
        ``file``, the ``marker`` read (its full name) and the ``rate_hz``.

    Raises:
        ValueError: (one line) for a header that is not a Nexus trajectories export's (which line, what it should
            be), a marker the file does not have (listing those it has), units other than mm, cm or m, a value that
            is not a number, frames that do not increase, a marker never tracked, or a gap longer than ``max_gap``.
    """
    path = Path(path)
    marker = FINGERTIP if marker is None else marker
    max_gap = MAX_GAP_S if max_gap is None else as_positive("max_gap", max_gap, "s")
    where = f"Nexus export {str(path)!r}"
    rows = _section(path, where)
    rate = _rate(rows[1], where)
    names, axes, units = rows[2], rows[3], rows[4]
    if [c.strip() for c in axes[:2]] != ["Frame", "Sub Frame"]:
        raise ValueError(f"{where}: line 4 must start with 'Frame,Sub Frame,X,Y,Z', it starts with {','.join(axes[:5])!r}")
    label = trial_label(path)
    column, full_name = _marker_column(names, _filled(marker, label, names, where), where)
    if [c.strip() for c in axes[column:column + 3]] != ["X", "Y", "Z"]:
        raise ValueError(f"{where}: marker {full_name!r} needs the columns X, Y, Z on line 4, has {axes[column:column + 3]}")
    stated = {u.strip() for u in units[column:column + 3]}
    if len(stated) != 1 or next(iter(stated)) not in UNITS_M:
        raise ValueError(f"{where}: marker {full_name!r} has the units {sorted(stated)} on line 5; allowed: "
                         f"{', '.join(UNITS_M)} (the same for X, Y and Z)")
    scale = UNITS_M[next(iter(stated))]
    data = rows[5:]
    if not data:
        raise ValueError(f"{where} has a header but no frames")
    frames = np.array([_number(row, 0, where, k) for k, row in enumerate(data, start=6)])
    position = np.array([[_number(row, c, where, k, missing=True) for c in range(column, column + 3)]
                         for k, row in enumerate(data, start=6)]) * scale
    samples = _checked(path.stem, (frames - frames[0]) / rate, _gaps_as_nan(position), where, check_units=False)
    seen = np.flatnonzero(samples.tracked)
    if seen.size == 0:
        raise ValueError(f"{where}: marker {full_name!r} is never tracked (every cell of its X, Y, Z is empty)")
    _check_gaps(samples, seen, frames, max_gap, full_name, where)
    if check_units:
        try:
            check_positions_m(samples.position[seen], f"{where}, marker {full_name!r} in {next(iter(stated))}")
        except ValueError as error:         # the file states its units: say they look wrong, do not refuse
            warnings.warn(str(error), stacklevel=2)
    label |= {"file": str(path), "marker": full_name, "rate_hz": rate}
    return the_reach(TrackedSamples(samples.name, samples.t, samples.position, label))


def the_reach(samples: TrackedSamples, rest: float = REST_S) -> TrackedSamples:
    """The samples of the movement that holds the peak speed, with the rests around it (module docstring): from the
    last sample of the movement before it (or the first sample) to the first sample of the movement after it (or the
    last). Speeds are those of :meth:`TrackedSamples.recording` (Savitzky–Golay); a movement ends where the speed
    stays below :data:`~comanip.recordings.preprocessing.ONSET_FRACTION` of the peak for ``rest`` s."""
    rest = as_positive("rest", rest, "s")
    moving = samples.recording()         # up to the end of the last movement: every sample after it is still
    speed = np.linalg.norm(moving.velocity, axis=1)
    still = np.r_[speed <= ONSET_FRACTION * speed.max(), False]
    peak = int(np.argmax(speed))
    edges = np.flatnonzero(np.diff(np.r_[False, still].astype(int)))
    runs = [(a, b) for a, b in zip(edges[::2], edges[1::2]) if moving.t[b - 1] - moving.t[a] >= rest - 1e-9]
    before = [a for a, b in runs if b <= peak and a > 0]
    after = [b for a, b in runs if a > peak and b < len(speed)]
    begin = moving.t[before[-1]] if before else -np.inf
    end = moving.t[after[0] - 1] if after else np.inf
    t = samples.t - samples.first_tracked
    keep = (t >= begin - 1e-9) & (t <= end + 1e-9)
    return TrackedSamples(samples.name, samples.t[keep], samples.position[keep], samples.label)


def load_nexus_trajectories(path: str | Path, marker: str | None = None, *, people=None, max_gap: float | None = None,
                            check_units: bool = True) -> list[TrackedSamples]:
    """The trials of a Nexus export or of a folder of them (module docstring), one :class:`TrackedSamples` per file.

    Args:
        path: an export, or a folder holding exports (in it or in one sub-folder per person).
        marker: as for :func:`read_nexus_trajectories`.
        people: the participants to read (e.g. ``["ADL001", "ADL002"]``); None: every one.
        max_gap: as for :func:`read_nexus_trajectories`.
        check_units: as for :func:`read_nexus_trajectories`.

    Returns:
        The trials by path, named ``"<participant>/<file stem>"`` (``"ADL001/ADL001FR1"``), each ``label`` with the
        ``participant``, ``task``, ``arm``, ``trial`` and ``target`` of :func:`trial_label`.
    """
    path = Path(path)
    files = [path] if path.is_file() else nexus_exports(path)
    if not files:
        raise ValueError(f"{str(path)!r} is neither a Nexus trajectories export nor a folder holding any "
                         f"(a CSV whose first line is {SECTION!r})")
    wanted = None if people is None else {str(p) for p in people}
    trials = []
    for file in files:
        if wanted is not None and trial_label(file)["participant"] not in wanted:
            continue
        samples = read_nexus_trajectories(file, marker, max_gap=max_gap, check_units=check_units)
        trials.append(TrackedSamples(f"{samples.label['participant']}/{samples.name}", samples.t, samples.position,
                                     samples.label))
    if not trials:
        raise ValueError(f"{str(path)!r} holds no Nexus exports of the people {sorted(wanted)}")
    return trials


def _section(path: Path, where: str) -> list[list[str]]:
    """The rows of the file's trajectories section: its five header lines and its frames, up to an empty row."""
    if not path.is_file():
        raise ValueError(f"{where} does not exist or is not a file")
    with open(path, newline="", encoding="utf-8-sig") as stream:
        rows = []
        for row in csv.reader(stream):
            if len(rows) >= 5 and not any(cell.strip() for cell in row):
                break
            rows.append(row)
    if not rows or not rows[0] or rows[0][0].strip() != SECTION:
        first = ",".join(rows[0])[:40] if rows else ""
        raise ValueError(f"{where}: line 1 must be {SECTION!r} (a Nexus trajectories export), it is {first!r}")
    if len(rows) < 5:
        raise ValueError(f"{where} has {len(rows)} lines; a Nexus export has 5 header lines (Trajectories, the rate, "
                         f"the marker names, Frame/Sub Frame/X/Y/Z, the units) before its frames")
    return rows


def _rate(row: list[str], where: str) -> float:
    text = row[0].strip() if row else ""
    try:
        rate = float(text)
    except ValueError:
        rate = math.nan
    if not math.isfinite(rate) or rate <= 0:
        raise ValueError(f"{where}: line 2 must be the frame rate in Hz (a number > 0), it is {text!r}")
    return rate


def _filled(marker: str, label: dict, names: list[str], where: str) -> str:
    """The marker's name with ``{arm}`` replaced by the arm of the file's name."""
    if "{arm}" not in marker:
        return marker
    if label["arm"] is None:
        raise ValueError(f"{where}: the marker {marker!r} names the arm of the file, but its name does not say it "
                         f"(<person><task><arm R|L><trial>.csv); name a marker (--marker), one of {_listing(names)}")
    return marker.replace("{arm}", label["arm"])


def _marker_column(names: list[str], marker: str, where: str) -> tuple[int, str]:
    """(X column, full name) of ``marker``, matched on the full name or on the name after the subject."""
    wanted = marker.strip()
    found = [(k, n.strip()) for k, n in enumerate(names)
             if n.strip() and (n.strip() == wanted or (":" not in wanted and n.strip().split(":")[-1] == wanted))]
    if not found:
        raise ValueError(f"{where} has no marker {wanted!r}; its markers: {_listing(names)}")
    if len(found) > 1:
        raise ValueError(f"{where} has the marker {wanted!r} on several subjects ({', '.join(n for _, n in found)}); "
                         f"name it with its subject")
    return found[0]


def _listing(names: list[str]) -> str:
    return ", ".join(n.strip() for n in names if n.strip()) or "none"


def _number(row: list[str], column: int, where: str, line: int, missing: bool = False) -> float:
    text = row[column].strip() if column < len(row) else ""
    if text == "" and missing:
        return math.nan
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{where}, line {line}, column {column + 1}: {text!r} is not a number") from None


def _check_gaps(samples: TrackedSamples, seen: np.ndarray, frames: np.ndarray, max_gap: float, marker: str,
                where: str) -> None:
    """ValueError when the longest run of lost frames between tracked ones lasts longer than ``max_gap`` s."""
    lost = np.diff(samples.t[seen]) - float(np.median(np.diff(samples.t)))
    longest = int(np.argmax(lost)) if lost.size else 0
    if lost.size and lost[longest] > max_gap + 1e-9:
        first, last = int(frames[seen[longest] + 1]), int(frames[seen[longest + 1] - 1])
        raise ValueError(f"{where}: marker {marker!r} is lost for {lost[longest]:.3g} s (frames {first}–{last}); gaps of "
                         f"up to max_gap = {max_gap:g} s are bridged (--max-gap)")
