"""Copy the ten arm reaches of this folder from a TAT-HUM development split (tathum/SOURCE.md says which and why).

    PYTHONPATH=src python examples/data/arm_reaches/copy_typical_reaches.py ../shared/data/arm_reaches/tathum

Of the reaches that play as a reach (:func:`comanip.simulation.recorded_person.usable_for_reach`), the five to each
target whose movement time is closest to the split's median (ties: the earlier trial), copied unchanged into
``tathum/data_3d`` with the trial log cut to its header and their rows, and the licence beside them. Prints the
median and the trials chosen.
"""

from __future__ import annotations

import argparse
import csv
import shutil
from pathlib import Path

import numpy as np

from comanip.recordings import load_tathum
from comanip.simulation.recorded_person import usable_for_reach

HERE = Path(__file__).resolve().parent
PER_TARGET = 5


def typical_trials(data_3d: Path) -> tuple[float, list[int]]:
    """The split's median movement time (s) and the chosen trial numbers, by target then trial."""
    reaches = [(trial.label, trial.recording()) for trial in load_tathum(data_3d)]
    reaches = [(label, recording) for label, recording in reaches if usable_for_reach(recording)]
    median = float(np.median([recording.movement_time for _, recording in reaches]))
    step = min(float(np.median(np.diff(recording.t))) for _, recording in reaches)
    chosen = []
    for target in sorted({label["target"] for label, _ in reaches}):
        ranked = sorted((round(abs(recording.movement_time - median) / step), label["trial"])
                        for label, recording in reaches if label["target"] == target)
        chosen += sorted(trial for _, trial in ranked[:PER_TARGET])
    return median, chosen


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("source", type=Path, help="the tathum folder of the development split (LICENSE, data_3d/)")
    source = parser.parse_args().source
    median, chosen = typical_trials(source / "data_3d")
    target = HERE / "tathum"
    shutil.rmtree(target / "data_3d", ignore_errors=True)
    for n in chosen:
        path = target / "data_3d" / "trajectory_data" / "par1" / f"par1_trial_{n}.csv"
        path.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source / "data_3d" / "trajectory_data" / "par1" / path.name, path)
    lines = (source / "data_3d" / "trial_data" / "par1_tathum.csv").read_text().splitlines(keepends=True)
    rows = list(csv.DictReader(lines))
    kept = [lines[0]] + [lines[k + 1] for k, row in enumerate(rows)
                         if row["trials.thisN"].strip() and int(float(row["trials.thisN"])) in chosen]
    (target / "data_3d" / "trial_data").mkdir(parents=True, exist_ok=True)
    (target / "data_3d" / "trial_data" / "par1_tathum.csv").write_text("".join(kept))
    shutil.copyfile(source / "LICENSE", target / "LICENSE")
    print(f"median movement time {median:.2f} s; trials {chosen}")


if __name__ == "__main__":
    main()
