"""``comanip validate``: the paper's validation analyses (Section IV-D, Fig. 3–5), the calibration study and the
human-likeness targets (issue 11, beside the paper's planar preset) on a point-mass preset, and the Franka
section (Section V-B: Panda reaches from the ready pose, hand speed, joint trajectories against their limits,
solve times), written as PNG figures, CSV files, ``report.json`` (every number) and ``report.md`` (tables).
With an arm preset (``--preset franka``) the run is the Franka section alone."""

from __future__ import annotations

import json

from comanip.cli.options import add_model_arguments, load_model
from comanip.cli.outputs import add_output_arguments, output_dir, write_manifest
from comanip.validation import ValidationSettings, run_validation


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("validate", help="run the validation analyses, the calibration study and the Franka section",
                                   description=__doc__)
    add_model_arguments(parser)
    add_output_arguments(parser, "out/validate")
    parser.add_argument("--quick", action="store_true",
                        help="fewer Monte Carlo samples, closed-loop trials and calibration configurations, three Franka "
                             "goals instead of six (about 30 s; about 110 s the first time, when the Panda's "
                             "functions are compiled and cached)")
    parser.add_argument("--no-franka", dest="franka", action="store_false",
                        help="skip the Franka section (no Panda planner is built)")
    parser.add_argument("--targets-reference", default="planar", metavar="PRESET",
                        help="point-mass preset or model YAML scored beside --preset on the human-likeness targets "
                             "(default: %(default)s)")
    parser.add_argument("--workers", type=int, help="processes for the calibration study (default: the CPU count)")
    parser.add_argument("--seed", type=int, default=0, help="seed of every random draw (default: %(default)s)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.plots.validation_figures import draw_validation_figures

    model = load_model(args)
    options = {"workers": args.workers, "seed": args.seed, "franka": args.franka, "human_reference": args.targets_reference}
    settings = ValidationSettings.quick_run(**options) if args.quick else ValidationSettings(**options)
    out = output_dir(args.out, "validate", args.force, create=False)
    # checks the model against the settings before creating out; the figures are drawn as a step of their own
    report = run_validation(model, out, settings, draw=draw_validation_figures)
    summary = {"model": model.name, "out": str(out)}
    if "fitts_grid" in report:
        grid = report["fitts_grid"]
        summary |= {"fitts_r2": grid["fits"]["fitts"]["r2"], "shannon_r2": grid["fits"]["shannon"]["r2"],
                    "configurations_with_fitts_law_and_early_peak": report["calibration"]["both"]}
    if "human_targets" in report:
        summary["human_targets_passed"] = {m["model"]: f"{m['passed']}/{m['targets']}" for m in report["human_targets"]["models"]}
    if "franka" in report:
        summary["franka"] = report["franka"]["summary"]
    files = ["report.json", "report.md", *report["figures"], *report.get("franka", {}).get("files", [])]
    write_manifest(out, "validate", [out / f for f in files])
    print(json.dumps(summary | {"files": files, "wall_time_s": round(report["wall_time_s"], 1)}, indent=1))
    return 0
