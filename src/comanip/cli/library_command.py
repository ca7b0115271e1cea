"""``comanip library``: solve an arm's reach library (plans from its ready pose to a grid of goals) and save it.

Cold solves from the ready pose then start from the nearest entries (``comanip.planning.starts.arm_reach_library``).
The ``franka_rest`` preset's library ships with the package; this makes one for another model (e.g. ``franka``,
or a YAML of your own; pass the file as ``SolverOptions(arm_library=...)``) or remakes the shipped one:

    comanip library --preset franka_rest --out src/comanip/data/reach_library_franka_rest.npz
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from comanip.cli.command_help import command_help
from comanip.cli.options import add_model_arguments, load_model
from comanip.planning.starts.arm_reach_library import FILE_PREFIX, GRID_SPACING, SHELL, build_library, grid_goals
from comanip.planning.planner import Planner, SolverOptions
from comanip.progress import progress_bar


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("library", help=command_help("library"),
                                   description=__doc__)
    add_model_arguments(parser, default_preset="franka_rest")
    parser.add_argument("--spacing", type=float, default=GRID_SPACING, help="grid spacing of the goals (m) (default: %(default)s)")
    parser.add_argument("--shell", type=float, nargs=2, default=SHELL, metavar=("INNER", "OUTER"),
                        help="goals' distances from the ready pose's hand (m) (default: %(default)s)")
    parser.add_argument("--out", help=f"the .npz to write (default: {FILE_PREFIX}<model name>.npz)")
    parser.set_defaults(func=run)


def run(args) -> int:
    model = load_model(args)
    if model.body.is_linear:
        raise ValueError(f"--preset: {model.name!r} is a point mass; its cold solves start from turned reaches "
                         "(no library file needed). A library is for arms (e.g. franka, franka_rest)")
    inner, outer = args.shell
    if not (np.isfinite(args.spacing) and args.spacing > 0):
        raise ValueError(f"--spacing must be a positive distance in m, got {args.spacing}")
    if not (0 <= inner < outer and np.isfinite(outer)):
        raise ValueError(f"--shell must be two distances 0 ≤ INNER < OUTER (m), got {inner} {outer}")
    out = Path(args.out or f"{FILE_PREFIX}{model.name}.npz")
    if out.suffix != ".npz" or out.is_dir() or not out.parent.is_dir():
        raise ValueError(f"--out must be a .npz file in an existing folder, got {str(out)!r}")
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    goals = grid_goals(hand, args.spacing, (inner, outer))
    planner = Planner(model, SolverOptions(cold_search="all"))
    began = time.perf_counter()
    with progress_bar("library goals", total=len(goals), unit="goal") as bar:
        library = build_library(model, lambda start, goal, warm: planner.solve(start, goal, warm_start=warm), goals,
                                progress=lambda done: bar.update(done - bar.n))
    path = library.save(out)
    print(json.dumps({"model": model.name, "goals": len(goals), "entries": len(library.goals),
                      "seconds": round(time.perf_counter() - began, 1), "file": str(path)}, indent=1))
    return 0
