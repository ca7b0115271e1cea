"""Command-line options shared by the subcommands: argparse helpers for the model and a reach, loading the
model, and parsing input paths and vectors. Checks of argument values for the library are in
:mod:`comanip.arguments`."""

from __future__ import annotations

import argparse
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from comanip import presets
from comanip.arguments import as_scheduler_address
from comanip.cli.outputs import add_output_arguments

if TYPE_CHECKING:
    from comanip.model import ReachingModel


def add_model_arguments(parser: argparse.ArgumentParser, default_preset: str = "planar") -> None:
    parser.add_argument("--preset", default=default_preset,
                        help=f"built-in preset ({', '.join(presets.names())}) or a model YAML file (default: %(default)s)")


def add_reach_arguments(parser: argparse.ArgumentParser, start_default: str, out_default: str, figures: str) -> None:
    """Arguments of the subcommands that solve one reach and write it: --start (whose default is described
    by ``start_default``), --width, --max-wall-time, --out (default ``out_default``), --force and --png (``figures``)."""
    parser.add_argument("--start", type=vector, help=f"start state [q; qdot], comma-separated (default: {start_default})")
    parser.add_argument("--width", type=float, help="goal width (m) (default: the preset's)")
    parser.add_argument("--max-wall-time", type=float, help="solve budget (s)")
    add_output_arguments(parser, out_default)
    parser.add_argument("--png", action="store_true", help=f"also save {figures}")


def reach_of(model: ReachingModel, start, goal, reach_m: float) -> tuple[np.ndarray, np.ndarray]:
    """The start (at rest at the body's home position when None) and goal (``reach_m`` along x from the start's hand
    when None) of a command's reach, as given otherwise; checked by the caller."""
    from comanip.planning.planner import reach_inputs

    start = np.concatenate([model.body.home_position, np.zeros(model.n)]) if start is None else start
    if goal is None:
        start_q = reach_inputs(model, start, np.zeros(model.d), None)[0][: model.n]
        goal = np.asarray(model.body.kinematics_function(start_q)[0]).ravel() + reach_m * np.eye(model.d)[0]
    return start, goal


def add_unit_check_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """--skip-unit-check: read ``what`` as s and m even when its times look like ms or its positions like mm."""
    parser.add_argument("--skip-unit-check", dest="check_units", action="store_false",
                        help=f"read {what} as seconds and metres (radians for joints) even where the times look like "
                             "ms or the positions like mm")


def add_bag_arguments(parser: argparse.ArgumentParser, what: str) -> None:
    """--topic and --frame: which samples of a ROS 2 bag given as ``what`` are the hand's."""
    parser.add_argument("--topic", help=f"the hand's topic when {what} is a ROS 2 bag (PoseStamped, PointStamped, TransformStamped "
                                        "or TFMessage; default: the bag's only such topic)")
    parser.add_argument("--frame", help=f"when {what} is a bag: the frame of the positions (poses, points) or the hand's "
                                        "child frame (transforms) (default: the topic's only frame)")


def add_marker_arguments(parser: argparse.ArgumentParser, what: str) -> None:
    """--marker and --max-gap: which marker of a Vicon Nexus export given as ``what`` is the hand's, and the longest
    gap in it that is bridged."""
    parser.add_argument("--marker", help=f"the hand's marker when {what} is a Vicon Nexus trajectories export (or a folder "
                                         "of them), with or without its subject; {arm} is the arm of the file's name "
                                         "(default: {arm}FTP, the fingertip of the arm that reached)")
    from comanip.recordings.nexus_trajectories import MAX_GAP_S

    parser.add_argument("--max-gap", type=float, help=f"when {what} is a Nexus export: the longest gap (s) of the marker "
                                                      f"that is bridged by interpolation (default: {MAX_GAP_S:g})")


def load_model(args: argparse.Namespace) -> ReachingModel:
    """The model named by --preset; a ValueError names the argument."""
    try:
        return presets.load(args.preset)
    except ValueError as error:
        raise ValueError(f"--preset: {error}") from None


def scheduler_address(text: str) -> str:
    """An argparse type: a Dask scheduler address (protocol://host:port), checked before any work is done."""
    try:
        return as_scheduler_address("--scheduler", text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def input_file(text: str) -> Path:
    """An argparse type: a path to an existing, readable, non-empty file (not a directory)."""
    return _readable(Path(text), folders=False)


def input_file_or_bag(text: str) -> Path:
    """An argparse type: a path to an existing, readable, non-empty file, or to a ROS 2 bag's folder."""
    from comanip.recordings.ros_bags import is_bag

    path = Path(text)
    return path if path.is_dir() and is_bag(path) else _readable(path, folders=False)


def input_file_or_folder(text: str) -> Path:
    """An argparse type: a path to an existing, readable, non-empty file, or to a folder."""
    return _readable(Path(text), folders=True)


def _readable(path: Path, folders: bool) -> Path:
    wanted = "a file or a folder" if folders else "a file"
    if not path.exists():
        raise argparse.ArgumentTypeError(f"{str(path)!r} does not exist; expected {wanted}")
    if path.is_dir():
        if folders:
            return path
        raise argparse.ArgumentTypeError(f"{str(path)!r} is a directory; expected a file")
    if not os.access(path, os.R_OK):
        raise argparse.ArgumentTypeError(f"{str(path)!r} is not readable (permissions)")
    if path.stat().st_size == 0:
        raise argparse.ArgumentTypeError(f"{str(path)!r} is empty")
    return path


def vector(text: str) -> np.ndarray:
    """Parse '0.3,0' or '0.3 0' into a float array."""
    try:
        return np.array([float(v) for v in text.replace(",", " ").split()])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None
