"""List the files of the package one online update enters, and the functions it calls in each:

    python -m tools.update_files            # a shipped arm reach, streamed through ReachStream, at half its movement

The reach is the first of the recorded arm reaches shipped in ``examples/data/arm_reaches/`` (TAT-HUM layout),
streamed as a live tracker delivers it with the ``arm`` preset; every sample up to half of its movement time is
given, and the next one's :meth:`~comanip.estimation.ReachStream.update` is traced with ``sys.setprofile``: the files
under ``src/comanip/`` whose code it calls, with the names of those functions. What `docs/architecture.md` says
of an update's path reads this.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import comanip
from comanip.estimation import ReachStream
from comanip.recordings import load_tathum

SHIPPED_ARM_REACHES = Path(__file__).resolve().parents[1] / "examples" / "data" / "arm_reaches" / "tathum" / "data_3d"
"""The recorded arm reaches shipped with the source (TAT-HUM layout)."""


def traced_update() -> tuple[str, dict[str, set[str]]]:
    """The traced update's status and {file under the package: names of the functions it called there}."""
    recording = load_tathum(SHIPPED_ARM_REACHES)[0].streamed_recording()
    stream = ReachStream(comanip.presets.load("arm"))
    middle = int(np.searchsorted(recording.t, 0.5 * (recording.onset + recording.end_time)))
    for k in range(middle):
        stream.update(recording.t[k], recording.position[k], recording.velocity[k])
    root = str(Path(comanip.__file__).parent) + "/"
    calls: dict[str, set[str]] = {}

    def called(frame, event, _):
        if event == "call" and frame.f_code.co_filename.startswith(root):
            calls.setdefault(frame.f_code.co_filename[len(root):], set()).add(frame.f_code.co_name)

    sys.setprofile(called)
    try:
        step = stream.update(recording.t[middle], recording.position[middle], recording.velocity[middle])
    finally:
        sys.setprofile(None)
    return str(step.estimate.status), calls


def main() -> int:
    status, calls = traced_update()
    print(f"one update at half of a shipped arm reach's movement (estimate {status}) enters {len(calls)} files:")
    for name in sorted(calls):
        print(f"  {name}: {', '.join(sorted(calls[name]))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
