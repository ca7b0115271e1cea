"""``comanip handover``: plan the robot-led reach, predict the transition, and write the impedance schedule.

For each goal: plan with the Cartesian preset, find when the planned hand comes within the predicted
transition distance of the goal, ramp the translational stiffness from 400 N/m to 0 there, and save the
rest-position trajectory and stiffness (JSON and CSV, optionally resampled to a controller rate) and one
figure over distance to the goal (paper Fig. 8 layout).
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from comanip.arguments import as_optional_positive, as_positive
from comanip.cli.command_help import command_help
from comanip.cli.options import add_model_arguments, input_file, load_model, vector
from comanip.cli.outputs import add_output_arguments, output_dir, point_text, report, warn, write_manifest
from comanip.multicomponent.handover import DEFAULT_RAMP_TIME, LEADING_STIFFNESS, check_schedule_arguments, plan_handover
from comanip.multicomponent.transition_data import ARM_LENGTH

DEFAULT_GOALS = ("0.2,0.1,0", "0.4,0.25,-0.1")
"""A near and a far goal from the origin (m), as in the paper's experiment (Fig. 8)."""


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("handover", help=command_help("handover"),
                                   description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_model_arguments(parser, default_preset="cartesian")
    parser.add_argument("--start", type=vector, help="start state [x; xdot] (m, m/s), comma-separated (default: at rest at the origin)")
    parser.add_argument("--goal", type=vector, action="append",
                        help=f"goal position (m), comma-separated; repeat for several (default: {' and '.join(DEFAULT_GOALS)})")
    parser.add_argument("--width", type=float, help="goal width (m) (default: the preset's)")
    parser.add_argument("--ramp-time", type=float, default=DEFAULT_RAMP_TIME,
                        help="stiffness ramp to 0 (s); 0 switches at once (default: %(default)s)")
    parser.add_argument("--stiffness", type=float, default=LEADING_STIFFNESS,
                        help="translational stiffness while the robot leads (N/m) (default: %(default)s)")
    parser.add_argument("--rate", type=float, help="resample the schedule at this controller rate (Hz), e.g. 1000")
    parser.add_argument("--transition-model", type=input_file, help="a model JSON from 'comanip transition fit' (default: fit on the shipped data)")
    parser.add_argument("--arm-length", type=float,
                        help=f"arm length L (m) that normalises the goal distance (default: the model's, {ARM_LENGTH} for the shipped one)")
    parser.add_argument("--max-wall-time", type=float, help="planning budget per goal (s)")
    add_output_arguments(parser, "out/handover")
    parser.add_argument("--no-plot", action="store_true", help="skip the figure")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.multicomponent.transition_model import ExtrapolationWarning, TransitionModel
    from comanip.planning.planner import Planner, reach_inputs

    check_schedule_arguments(args.ramp_time, args.stiffness, args.rate)
    arm_length = None if args.arm_length is None else as_positive("arm_length", args.arm_length, "m")
    model = load_model(args)
    start = np.zeros(2 * model.n) if args.start is None else args.start
    goals = args.goal or [vector(g) for g in DEFAULT_GOALS]
    as_optional_positive("max_wall_time", args.max_wall_time, "s")
    for goal in goals:  # every input checked before the transition model is fitted, a planner built or the folder made
        reach_inputs(model, start, goal, args.width)
    out = output_dir(args.out, "handover", args.force, create=False)
    transition = TransitionModel.load(args.transition_model) if args.transition_model else TransitionModel()
    if arm_length is not None:
        transition.arm_length = arm_length
    planner = Planner(model)
    out.mkdir(parents=True, exist_ok=True)
    plans, schedules, results, written, lines = [], [], [], [], []
    for k, goal in enumerate(goals):
        plan = planner.solve(start, goal, args.width, max_wall_time=args.max_wall_time)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ExtrapolationWarning)
            schedule = plan_handover(plan, transition, ramp_time=args.ramp_time, leading_stiffness=args.stiffness,
                                     rate=args.rate)
        files = [schedule.save_json(out / f"handover_{k}.json"), schedule.save_csv(out / f"handover_{k}.csv")]
        plans.append(plan)
        schedules.append(schedule)
        warnings_k = plan.extras.get("warnings", []) + [str(w.message) for w in caught]
        warn("handover", [f"goal {k}: {text}" for text in warnings_k])
        results.append({**schedule.summary(), "plan_status": plan.status, "plan_success": plan.success,
                        "warnings": warnings_k, "files": [str(f) for f in files]})
        written += files
        lines.append(f"goal {k} {point_text(goal)} m: plan {plan.status}, release starts {schedule.transition_distance:.3g} m "
                     f"from the goal at t = {schedule.transition_time:.3g} s")
    if not args.no_plot:
        from comanip.plots.handover_figure import plot_handover

        figure = plot_handover(plans, schedules, out / "handover.png")
        results.append({"figure": str(figure)})
        written.append(figure)
    write_manifest(out, "handover", written)
    report(args, lines, results, out, written)
    return 0 if all(p.success for p in plans) else 1
