"""Fit the `people` preset: the `human` preset's motor noise (kappa) and discount (gamma) fitted to recorded
people's movement times against distance (the cursory development split, arm scale).

    PYTHONPATH=src python -m studies.do_the_presets_move_like_people.fit_people_preset [--out PATH]

The recordings carry no target width, so every condition takes the human preset's width (an effective
width); the median movement time of the development movements in four ranges of distance is the table fitted
(``comanip.fit_movement_times``). Writes the preset (default ``src/comanip/presets/people.yaml``) and
``people_fit.json`` beside this script.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
BINS = ((0.1, 0.2), (0.2, 0.3), (0.3, 0.45), (0.45, 0.7))


def main(argv=None):
    import comanip
    from comanip.fitting.movement_times import MovementTimeTable
    from comanip.recordings import load_cursory

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=HERE.parents[1] / "src" / "comanip" / "presets" / "people.yaml")
    args = parser.parse_args(argv)
    recordings = load_cursory("development")
    D = np.array([r.distance for r in recordings])
    MT = np.array([r.movement_time for r in recordings])
    distance = np.array([np.median(D[(D >= lo) & (D < hi)]) for lo, hi in BINS])
    mt = np.array([np.median(MT[(D >= lo) & (D < hi)]) for lo, hi in BINS])
    start = comanip.presets.human()
    table = MovementTimeTable(distance, np.full(len(BINS), start.width), mt)
    result = comanip.fit_movement_times(start, table, ("kappa", "gamma"), max_evaluations=60)
    print(result.status, result.values, result.std_errors)
    model = result.model.replace(name="people", description=(
        "The human preset with kappa and gamma fitted to recorded people's median movement times at four "
        "distances (cursory development split at arm scale, width 0.02 m as an effective width; "
        "studies/do_the_presets_move_like_people/fit_people_preset.py)."))
    comanip.presets.save(model, args.out)
    args.out.write_text("# Fitted to recorded people by studies/do_the_presets_move_like_people/fit_people_preset.py: rerun it\n"
                        "# rather than edit this file.\n" + args.out.read_text())
    (HERE / "people_fit.json").write_text(json.dumps({
        "status": str(result.status), "values": result.values, "std_errors": result.std_errors,
        "table": {"distance_m": distance.tolist(), "width_m": [start.width] * len(BINS), "mt_s": mt.tolist()}},
        indent=1, default=float))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
