"""``comanip fit``: fit a model's parameters to recorded reaches (maximum likelihood of their positions, or their
timing matched by the model's closed-loop reaches: ``--match timing``) or to movement times per condition (least
squares); write fit.json (values, standard errors, residuals, status), model.yaml
(readable by ``comanip plan --preset``) and fit.png. The formats and the method: docs/fitting.md."""

from __future__ import annotations

from comanip.arguments import as_count
from comanip.cli.command_help import command_help
from comanip.cli.options import (add_bag_arguments, add_marker_arguments, add_model_arguments, add_unit_check_argument,
                                 input_file, input_file_or_folder, load_model, scheduler_address)
from comanip.cli.outputs import add_output_arguments, output_dir, report, write_manifest
from comanip.fitting.parameters import DEFAULT_PARAMETERS, MT_DEFAULT_PARAMETERS, ParameterSpace


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("fit", help=command_help("fit"), description=__doc__)
    data = parser.add_mutually_exclusive_group(required=True)
    data.add_argument("--recordings", type=input_file_or_folder, help="recordings CSV (trial, t, x, y[, z], goal and width columns), "
                      "a folder of them, a ROS 2 bag of one trial (its goal and width from --trials), a motion-capture folder (TAT-HUM), "
                      "or a Vicon Nexus trajectories export or a folder of them")
    data.add_argument("--mt-table", type=input_file, help="movement-time CSV (distance_m, width_m, mt_s per condition)")
    parser.add_argument("--trials", type=input_file, help="trials table (trial, goal_x, goal_y[, goal_z], width) for recordings without goal columns")
    add_bag_arguments(parser, "--recordings")
    add_marker_arguments(parser, "--recordings")
    add_unit_check_argument(parser, "the recordings")
    add_model_arguments(parser)
    parser.add_argument("--parameters", type=names, help=f"free parameters, comma-separated model fields or sigma_obs "
                        f"(default: {','.join(DEFAULT_PARAMETERS)} for recordings, {','.join(MT_DEFAULT_PARAMETERS)} for an MT table)")
    parser.add_argument("--match", choices=("positions", "timing"), default="positions",
                        help="recordings: 'positions' maximises the likelihood of the recorded positions under one open-loop "
                        "plan per condition; 'timing' matches the mean MT and t_peak/MT of the model's closed-loop reaches "
                        "to the recordings' (default: %(default)s)")
    parser.add_argument("--width", type=float, help="goal width (m) of every recorded trial, instead of the recordings' "
                        "(a motion-capture folder's is its endpoints' spread)")
    parser.add_argument("--executions", type=int, default=8, help="--match timing: closed-loop executions per condition "
                        "(default: %(default)s)")
    parser.add_argument("--sigma-obs", type=float, default=1e-3, help="measurement-noise std (m) of the recordings (default: %(default)s)")
    parser.add_argument("--max-evaluations", type=int, help="optimiser evaluation budget (default: 200 for recordings' "
                        "positions, 60 for their timing, 100 for an MT table)")
    parser.add_argument("--scheduler", type=scheduler_address, help="Dask scheduler address (e.g. tcp://host:8786) to plan the conditions on (default: here)")
    add_output_arguments(parser, "out/fit")
    parser.add_argument("--no-progress", action="store_true", help="no progress line")
    parser.set_defaults(func=run)


def names(text: str) -> tuple[str, ...]:
    """'kappa, gamma' -> ('kappa', 'gamma')."""
    return tuple(name.strip() for name in text.split(",") if name.strip())


def run(args) -> int:
    from comanip.fitting.fit import fit_model
    from comanip.fitting.movement_times import MovementTimeTable, fit_movement_times
    from comanip.fitting.timing_fit import fit_timing
    from comanip.recordings.trial_files import load_recordings

    model = load_model(args)
    options = {"scheduler": args.scheduler, "progress": not args.no_progress}
    if args.max_evaluations is not None:
        options["max_evaluations"] = args.max_evaluations
    if args.parameters is not None:
        options["parameters"] = args.parameters
    # the arguments, then the data, are checked before the output folder is made
    as_count("--max-evaluations", args.max_evaluations, optional=True)
    timing = args.match == "timing"
    if timing and args.recordings is None:
        raise ValueError("--match timing goes with --recordings; an MT table is fitted by its movement times")
    as_count("--executions", args.executions)
    defaults = DEFAULT_PARAMETERS if args.recordings and not timing else MT_DEFAULT_PARAMETERS
    ParameterSpace(model, options.get("parameters", defaults), args.sigma_obs)
    if args.recordings is not None:
        data = load_recordings(args.recordings, args.trials, check_units=args.check_units, topic=args.topic, frame=args.frame,
                               marker=args.marker, max_gap=args.max_gap)
    elif any(value is not None for value in (args.trials, args.topic, args.frame, args.width, args.marker, args.max_gap)):
        raise ValueError("--trials, --width, --topic, --frame, --marker and --max-gap go with --recordings; an MT table "
                         "holds its conditions itself")
    else:
        data = MovementTimeTable.read(args.mt_table)
    out = output_dir(args.out, "fit", args.force)
    if timing:
        result = fit_timing(model, data, width=args.width, executions=args.executions, **options)
    elif args.recordings is not None:
        result = fit_model(model, data, sigma_obs=args.sigma_obs, width=args.width, **options)
    else:
        result = fit_movement_times(model, data, **options)
    written = [result.save_json(out / "fit.json"), result.save_yaml(out / "model.yaml")]
    if result.conditions:
        from comanip.plots.fit_figure import plot_fit

        written.append(plot_fit(result, out / "fit.png"))
    write_manifest(out, "fit", written)
    summary = {key: value for key, value in result.to_dict().items() if key not in ("model", "conditions", "trials")}
    lines = [f"fit ({model.name}): {result.summary()}"] + ([result.message] if result.message else [])
    report(args, lines, summary | {"files": [str(p) for p in written]}, out, written)
    return 0 if result.success else 1
