"""``comanip ros``: run the ROS 2 goal node, or replay a recording of hand states through it.

``comanip ros --params config.yaml`` starts the node (topics, rates, model and frame from the YAML, a flat
mapping of the node's parameters or ROS 2's ``node: {ros__parameters: ...}`` layout; ``--preset`` and
``--estimation-rate`` override the file's; ``--ros-args ...`` passes the rest to ROS, e.g. remappings).
``comanip ros --preset arm --estimation-rate 250`` estimates every pose of a 250 Hz tracker of a person's hand. ``--replay hand.csv`` instead feeds a CSV of hand states (the
format ``comanip estimate --observations`` reads; or a ROS 2 bag of the hand's position) through the node in-process, at ``--speed`` times real
time or in lock step with it (the default), and writes what it published to ``--out``. Needs the 'ros'
extra: pip install 'comanip[ros]'.
"""

from __future__ import annotations

import argparse
import dataclasses

from comanip.arguments import as_positive
from comanip.cli.command_help import command_help
from comanip.cli.options import add_bag_arguments, add_unit_check_argument, input_file, input_file_or_bag
from comanip.cli.outputs import add_output_arguments, output_dir, report, write_manifest
from comanip.extras import missing


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("ros", help=command_help("ros"), description=__doc__,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--params", type=input_file, help="the node's parameters, a YAML file (default: the defaults)")
    parser.add_argument("--preset", help="the model, a preset name or a model YAML (default: the --params file's, else "
                                         "'cartesian'); e.g. 'arm' for recorded people's arms")
    parser.add_argument("--estimation-rate", type=float, metavar="HZ",
                        help="most estimates per second (default: the --params file's, else 20); the tracker's rate, "
                             "e.g. 250, estimates every pose")
    parser.add_argument("--replay", type=input_file_or_bag, help="replay this CSV of hand states (t_s, q0.., qdot0..), or a ROS 2 "
                                                             "bag of the hand's position, through the node")
    add_bag_arguments(parser, "--replay")
    add_unit_check_argument(parser, "the --replay CSV")
    parser.add_argument("--speed", type=float, help="replay at this multiple of real time (default: in lock step with the node)")
    add_output_arguments(parser, "out/ros", "replay output folder")
    parser.add_argument("--ros-args", nargs=argparse.REMAINDER, default=[], help="everything after it goes to ROS (remappings, -p name:=value)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.ros.node_settings import NodeSettings

    settings = NodeSettings.from_yaml(args.params) if args.params is not None else NodeSettings()
    overrides = {name: value for name, value in (("preset", args.preset), ("estimation_rate", args.estimation_rate))
                 if value is not None}
    settings = dataclasses.replace(settings, **overrides) if overrides else settings
    speed = None if args.speed is None else as_positive("--speed", args.speed, "times real time")
    if speed is not None and args.replay is None:
        raise ValueError("--speed sets the pace of a --replay; give --replay CSV with it (the live node runs at its inputs' pace)")
    absent = missing("ros")
    if absent is not None:
        raise absent
    if args.replay is not None:
        from comanip.ros.replay import replay_csv

        out = output_dir(args.out, "ros", args.force, create=False)     # made once the replay CSV is read
        recording, written = replay_csv(settings, args.replay, out, speed, check_units=args.check_units, topic=args.topic,
                                        frame=args.frame)
        write_manifest(out, "ros", written)
        last = recording.statuses[-1][3] if recording.statuses else {}
        full = {"estimates": len(recording.goals), "last_goal_m": recording.goals[-1][1].tolist() if recording.goals else None,
                "rejected": int(last.get("rejected", 0)), "failed": int(last.get("failed", 0)),
                "wall_time_s": recording.wall_time, "files": [str(p) for p in written]}
        report(args, [f"ros replay: {full['estimates']} goal estimates published ({full['rejected']} inputs rejected, "
                      f"{full['failed']} failed solves) in {recording.wall_time:.3g} s"], full, out, written)
        return 0 if recording.goals else 1
    from comanip.ros.node import spin

    return spin(settings, args.ros_args)
