"""Fit the people endpoint models that ship with comanip (comanip/data/people_endpoint_<kind>.npz): the mouse
model on the development split of the cursory mouse recordings, the arm model on the motion-capture arm
reaches of a TAT-HUM data folder (its development split); never on held-out data.

    PYTHONPATH=src python -m studies.how_far_beyond_the_hand_do_people_stop.fit_people_model --kind mouse
    PYTHONPATH=src python -m studies.how_far_beyond_the_hand_do_people_stop.fit_people_model --kind arm \
        --arms ../shared/data/arm_reaches/tathum/data_3d

The mouse model needs the data extra (pip install -e ".[data]"); each fit takes about a minute.
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from comanip.estimation.people.people_model import KINDS, PeopleModel
from comanip.recordings import load_cursory, load_tathum


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kind", choices=sorted(KINDS), default="mouse")
    parser.add_argument("--arms", type=Path, default=None, help="a TAT-HUM 3-D data folder (for --kind arm)")
    parser.add_argument("--out", type=Path, default=None, help="default: the shipped model of the kind")
    args = parser.parse_args(argv)
    if args.kind == "mouse":
        recordings = load_cursory("development")
        source = f"cursory 2.1.0 development split ({len(recordings)} movements)"
    else:
        if args.arms is None:
            parser.error("--kind arm needs --arms FOLDER")
        recordings = [trial.streamed_recording() for trial in load_tathum(args.arms)]   # as a live tracker delivers them
        source = f"TAT-HUM 3-D demo data, development split ({len(recordings)} reaches)"
    out = args.out or Path(str(resources.files("comanip") / "data" / f"people_endpoint_{args.kind}.npz"))
    print(f"fitting on {len(recordings)} movements ...", flush=True)
    model = PeopleModel.fit(recordings, kind=args.kind, trained_on=source, progress=lambda line: print(f"  {line}", flush=True))
    phases = ", ".join(f"{factor:.3f}" for factor in model.phase_factors) or "one phase"
    print(f"features {', '.join(model.features)}; coverage factor {model.coverage_factor:.3f} (per phase: {phases}); "
          f"wrote {model.save(out)}")


if __name__ == "__main__":
    main()
