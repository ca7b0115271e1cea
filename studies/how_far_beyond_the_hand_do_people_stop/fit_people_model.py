"""Fit the people endpoint model that ships with comanip (comanip/data/people_endpoint_model.pkl) on the
development split of the cursory mouse recordings (never on the held-out split).

    PYTHONPATH=src python studies/how_far_beyond_the_hand_do_people_stop/fit_people_model.py [--out PATH]

Needs the data extra (pip install -e ".[data]"); takes about a minute.
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from comanip.estimation.people_model import SHIPPED, PeopleModel
from comanip.recordings import load_cursory


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path(str(resources.files("comanip") / "data" / SHIPPED)))
    args = parser.parse_args(argv)
    recordings = load_cursory("development")
    print(f"fitting on {len(recordings)} development movements ...", flush=True)
    model = PeopleModel.fit(recordings, trained_on=f"cursory 2.1.0 development split ({len(recordings)} movements)",
                            progress=lambda line: print(f"  {line}", flush=True))
    print(f"coverage factor {model.coverage_factor:.3f}; wrote {model.save(args.out)}")


if __name__ == "__main__":
    main()
