"""``comanip plan``: plan one reach and write it as JSON and CSV (and a PNG figure on request)."""

from __future__ import annotations

import numpy as np

from comanip.cli.command_help import command_help
from comanip.cli.options import add_model_arguments, add_reach_arguments, load_model, reach_of, vector
from comanip.cli.outputs import output_dir, point_text, report, warn, write_manifest


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("plan", help=command_help("plan"), description=__doc__)
    add_model_arguments(parser)
    add_reach_arguments(parser, "at rest at the body's home position: the origin for a point mass, the ready pose for the Panda",
                        "out/plan", "a figure")
    parser.add_argument("--goal", type=vector, help="goal position (m), comma-separated (default: 0.3 m along x from the start)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.arguments import as_optional_positive
    from comanip.planning.planner import Planner, reach_inputs

    model = load_model(args)
    start, goal = reach_of(model, args.start, args.goal, 0.3)
    reach_inputs(model, start, goal, args.width)  # every input checked before the folder is made
    as_optional_positive("max_wall_time", args.max_wall_time, "s")
    out = output_dir(args.out, "plan", args.force)
    plan = Planner(model).solve(start, goal, args.width, max_wall_time=args.max_wall_time)
    plan.save_json(out / "plan.json")
    plan.save_csv(out / "plan.csv")
    written = [out / "plan.json", out / "plan.csv"]
    if args.png:
        from comanip.plots.plan_figure import plot_plan

        written.append(plot_plan(plan, out / "plan.png"))
    write_manifest(out, "plan", written)
    warn("plan", plan.extras.get("warnings", []))
    full = {"model": model.name, "goal": np.asarray(plan.goal).tolist(), "width": plan.width,
            "success": plan.success, "status": plan.status, "message": plan.message, "objective": plan.objective,
            "solve_time_s": plan.solve_time, "iterations": plan.iterations, "final_error_m": plan.final_error,
            "reaches_goal": plan.reaches_goal, "peak_hand_speed_m_s": float(plan.ee_speed.max()),
            "warnings": plan.extras.get("warnings", []), "files": [str(p) for p in written]}
    lines = [f"plan ({model.name}): {plan.status}, goal {point_text(plan.goal)} m, final error {1e3 * plan.final_error:.3g} mm, "
             f"peak hand speed {plan.ee_speed.max():.3g} m/s, solved in {plan.solve_time:.3g} s"]
    report(args, lines, full, out, written)
    return 0 if plan.success else 1
