"""``comanip validate``: the paper's validation analyses (Section IV-D, Fig. 3–5), the calibration study and the
human-likeness targets (scored beside the paper's planar preset) on a point-mass preset, and the Franka
section (Section V-B: Panda reaches from the ready pose, hand speed, joint trajectories against their limits,
solve times), written as PNG figures, CSV files, ``report.json`` (every number) and ``report.md`` (tables).
With an arm preset (``--preset franka``) the run is the Franka section alone."""

from __future__ import annotations

from pathlib import Path

from comanip.cli.command_help import command_help
from comanip.cli.options import add_model_arguments, load_model
from comanip.cli.outputs import add_output_arguments, output_dir, report, write_manifest


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("validate", help=command_help("validate"),
                                   description=__doc__)
    add_model_arguments(parser)
    add_output_arguments(parser, None, default_text="out/validate/<preset>, e.g. out/validate/planar")
    parser.add_argument("--quick", action="store_true",
                        help="fewer Monte Carlo samples, closed-loop trials and calibration configurations, three Franka "
                             "goals instead of six (the first run takes longer: it compiles and caches the Panda's "
                             "functions)")
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
    from comanip.validation import ValidationSettings, run_validation
    from comanip.validation.paper_comparison import comparison_lines, paper_comparison

    model = load_model(args)
    options = {"workers": args.workers, "seed": args.seed, "franka": args.franka, "human_reference": args.targets_reference}
    settings = ValidationSettings.quick_run(**options) if args.quick else ValidationSettings(**options)
    out = output_dir(args.out or default_folder(args.preset), "validate", args.force, create=False)
    # checks the model against the settings before creating out; the figures are drawn as a step of their own
    results = run_validation(model, out, settings, draw=draw_validation_figures)
    summary = {"model": model.name, "out": str(out)}
    lines = [f"validate ({model.name}): the paper's analyses on this model, {results['wall_time_s']:.1f} s",
             *comparison_lines(results)]
    if "fitts_grid" in results:
        grid = results["fitts_grid"]
        summary |= {"paper_comparison": paper_comparison(results), "fitts_r2": grid["fits"]["fitts"]["r2"],
                    "shannon_r2": grid["fits"]["shannon"]["r2"],
                    "configurations_with_fitts_law_and_early_peak": results["calibration"]["both"]}
    if "human_targets" in results:
        summary["human_targets_within_range"] = {m["model"]: f"{m['passed']}/{m['targets']}" for m in results["human_targets"]["models"]}
    if "franka" in results:
        summary["franka"] = results["franka"]["summary"]
    files = ["report.json", "report.md", *results["figures"], *results.get("franka", {}).get("files", [])]
    write_manifest(out, "validate", [out / f for f in files])
    lines.append(f"the comparison and every table: {out / 'report.md'}")
    report(args, lines, summary | {"files": files, "wall_time_s": round(results["wall_time_s"], 1)}, out, files)
    return 0


def default_folder(preset: str) -> Path:
    """out/validate/<preset name>: 'planar' or the YAML file's name without its extension."""
    return Path("out/validate") / Path(preset).stem
