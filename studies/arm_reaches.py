"""The development arm reaches the arm studies measure, streamed as a live tracker delivers them (as in
benchmarks/real_people.py --source arms), read from the command line's ``--arms FOLDER`` (default: the shared
data beside the repository) and ``--limit N`` (at most N reaches)."""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from comanip.recordings import Recording, load_tathum

ARMS = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"


def streamed_arm_reaches(description: str, argv=None) -> list[Recording]:
    """The reaches the command line ``argv`` names (module docstring); exits with a one-line message where the
    folder is missing. Warnings are silenced: a study reads every reach, plausible or not."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--arms", type=Path, default=ARMS, help="a TAT-HUM 3-D data folder (trajectory_data/, trial_data/)")
    parser.add_argument("--limit", type=int, default=None, help="at most this many reaches")
    args = parser.parse_args(argv)
    if not args.arms.is_dir():
        sys.exit(f"no arm reaches at {args.arms}")
    warnings.simplefilter("ignore")
    return [trial.streamed_recording() for trial in load_tathum(args.arms)[:args.limit]]
