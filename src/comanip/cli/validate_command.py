"""``comanip validate``: the paper's validation analyses (Section IV-D, Fig. 3–5) and the calibration study on
a preset, written as PNG figures, ``report.json`` (every number) and ``report.md`` (tables)."""

from __future__ import annotations

import json

from comanip.cli.arguments import add_model_arguments, load_model, output_dir
from comanip.validation import ValidationSettings, run_validation


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("validate", help="run the validation analyses and the calibration study",
                                   description=__doc__)
    add_model_arguments(parser)
    parser.add_argument("--out", default="out/validate", help="output folder (default: %(default)s)")
    parser.add_argument("--quick", action="store_true",
                        help="fewer Monte Carlo samples, closed-loop trials and calibration configurations (well under a minute)")
    parser.add_argument("--workers", type=int, help="processes for the calibration study (default: the CPU count)")
    parser.add_argument("--seed", type=int, default=0, help="seed of every random draw (default: %(default)s)")
    parser.set_defaults(func=run)


def run(args) -> int:
    model = load_model(args)
    options = {"workers": args.workers, "seed": args.seed}
    settings = ValidationSettings.quick_run(**options) if args.quick else ValidationSettings(**options)
    out = output_dir(args.out)
    report = run_validation(model, out, settings)
    grid = report["fitts_grid"]
    print(json.dumps({"model": model.name, "out": str(out), "fitts_r2": grid["fits"]["fitts"]["r2"],
                      "shannon_r2": grid["fits"]["shannon"]["r2"],
                      "calibration_both": report["calibration"]["both"],
                      "files": ["report.json", "report.md", *report["figures"]],
                      "wall_time_s": round(report["wall_time_s"], 1)}, indent=1))
    return 0
