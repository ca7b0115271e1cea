"""``comanip transition generate|fit|plot``: the transition-point data, its Gaussian-process model, Fig. 2.

    comanip transition generate --out data.csv      # simulate the two-component person over a (D/L, w) grid
        [--preset NAME_OR_YAML]                     # ... made by any point-mass model (default: planar)
    comanip transition fit [--data data.csv]        # fit the GP (default: the shipped data), check the trends;
                                                    # prints the model that made the data (from the JSON beside it)
    comanip transition plot [--model model.json]    # Fig. 2: predicted transition distance over (D/L, w)
"""

from __future__ import annotations

import argparse
import json
import platform
import shlex
import sys
import time
from pathlib import Path

from comanip.cli.command_help import command_help
from comanip.cli.options import add_model_arguments, input_file, load_model, vector
from comanip.cli.outputs import add_output_arguments, output_dir, report, write_manifest
from comanip.multicomponent.transition_csv import read_transition_metadata, shipped_dataset_path, write_transition_csv
from comanip.multicomponent.transition_data import ARM_LENGTH, checked_sweep, generate_transition_data

DEFAULT_DISTANCES = "0.2,0.3,0.4,0.5,0.6,0.7,0.8"
DEFAULT_WIDTHS = "0.005,0.01,0.02,0.03,0.04,0.05"


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("transition", help=command_help("transition"),
                                   description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    actions = parser.add_subparsers(dest="action", required=True)

    generate = actions.add_parser("generate", help="simulate the closed-loop person and write the transition CSV")
    add_model_arguments(generate)
    generate.add_argument("--distances", type=vector, default=vector(DEFAULT_DISTANCES),
                          help=f"goal distances D/L, comma-separated (default: {DEFAULT_DISTANCES})")
    generate.add_argument("--widths", type=vector, default=vector(DEFAULT_WIDTHS),
                          help=f"goal widths w (m), comma-separated (default: {DEFAULT_WIDTHS})")
    generate.add_argument("--trials", type=int, default=30, help="closed-loop reaches per condition (default: %(default)s)")
    generate.add_argument("--arm-length", type=float, default=ARM_LENGTH, help="arm length L (m) (default: %(default)s)")
    generate.add_argument("--steps", type=int, help="executed steps per reach (default: 2H)")
    generate.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    generate.add_argument("--workers", type=int, default=2, help="worker processes (default: %(default)s)")
    add_output_arguments(generate, "out/transition/transition_data.csv", "CSV to write")
    generate.set_defaults(func=run_generate)

    fit = actions.add_parser("fit", help="fit the transition model and report the published trends")
    fit.add_argument("--data", type=input_file, help="transition CSV (default: the shipped dataset)")
    fit.add_argument("--arm-length", type=float, default=ARM_LENGTH, help="arm length L (m) for queries in metres (default: %(default)s)")
    add_output_arguments(fit, "out/transition", "output folder for model.json and trends.json")
    fit.set_defaults(func=run_fit)

    plot = actions.add_parser("plot", help="Fig. 2: the predicted transition distance over (D/L, w) with the data")
    plot.add_argument("--model", type=input_file, help="a model JSON written by 'fit' (default: fit on --data)")
    plot.add_argument("--data", type=input_file, help="transition CSV to fit when no --model is given (default: the shipped dataset)")
    add_output_arguments(plot, "out/transition/transition_model.png", "PNG to write")
    plot.set_defaults(func=run_plot)


def run_generate(args) -> int:
    sweep = checked_sweep(args.distances, args.widths, args.trials, model=load_model(args), arm_length=args.arm_length,
                          steps=args.steps, seed=args.seed, workers=args.workers)
    model, steps = sweep.model, sweep.steps
    folder = output_dir(Path(args.out).parent, "transition", args.force)
    began = time.perf_counter()
    rows = generate_transition_data(*sweep[:3], model=model, arm_length=sweep.arm_length, steps=steps, seed=sweep.seed,
                                    workers=sweep.workers)
    metadata = {
        "command": "comanip " + shlex.join(sys.argv[1:]) if Path(sys.argv[0]).name == "comanip" else shlex.join(sys.argv),
        "seed": args.seed, "model": model.config(), "arm_length_m": args.arm_length, "steps": steps,
        "trials_per_condition": args.trials, "distances_over_arm_length": args.distances.tolist(),
        "widths_m": args.widths.tolist(), "workers": args.workers,
        "wall_time_s": round(time.perf_counter() - began, 1), "python": platform.python_version(),
        "person": "closed-loop receding-horizon reacher (comanip.execution.execute_receding_horizon), start at rest "
                  "at the origin, goal D along x",
    }
    path = write_transition_csv(rows, args.out, metadata)
    written = [path, path.with_suffix(".json")]
    write_manifest(folder, "transition", written, action="generate")
    unsettled = sum(r["n_trials"] - r["settled_trials"] for r in rows)
    failed = sum(r["failed_replans"] for r in rows)
    report(args, [f"transition generate ({model.name}): {len(rows)} conditions in {metadata['wall_time_s']} s, "
                  f"{unsettled} unsettled trials, {failed} failed replans"],
           {"rows": len(rows), "csv": str(path), "metadata": str(path.with_suffix(".json")), "wall_time_s": metadata["wall_time_s"],
            "unsettled_trials": unsettled, "failed_replans": failed}, folder, written)
    return 0


def run_fit(args) -> int:
    from comanip.multicomponent.transition_model import TransitionModel
    from comanip.multicomponent.trends import trend_report

    data = args.data or shipped_dataset_path()
    out = output_dir(args.out, "transition", args.force, create=False)   # checked before the model is fitted
    model = TransitionModel(data, arm_length=args.arm_length)
    out.mkdir(parents=True, exist_ok=True)
    model.save(out / "model.json")
    trends = trend_report(model)
    (out / "trends.json").write_text(json.dumps(trends, indent=1))
    written = [out / "model.json", out / "trends.json"]
    write_manifest(out, "transition", written, action="fit")
    made = read_transition_metadata(data)
    made_by = None if made is None else {"model": made.get("model", {}).get("name"), "command": made.get("command")}
    rows = len(model.training_data["width_m"])
    report(args, [f"transition fit: {rows} rows of {data}, kernel {model.kernel_description}"],
           {"data": str(data), "data_made_by": made_by, "rows": rows, "kernel": model.kernel_description,
            "trends": trends, "files": [str(p) for p in written]}, out, written)
    return 0


def run_plot(args) -> int:
    from comanip.multicomponent.transition_model import TransitionModel
    from comanip.plots.transition_figure import plot_transition_model

    folder = output_dir(Path(args.out).parent, "transition", args.force, create=False)   # checked before the model is fitted
    model = TransitionModel.load(args.model) if args.model else TransitionModel(args.data or shipped_dataset_path())
    folder.mkdir(parents=True, exist_ok=True)
    figure = plot_transition_model(model, args.out)
    write_manifest(folder, "transition", [figure], action="plot")
    report(args, ["transition plot: predicted transition distance over (D/L, w)"], {"figure": str(figure)}, folder, [figure])
    return 0

