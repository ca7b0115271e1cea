"""``comanip replan``: a reach replanned in closed loop at a controller's rate (the real-time iteration), beside the
same loop replanned to convergence every cycle; every cycle's time and the executed path as CSV, a summary as JSON
(and a PNG figure on request)."""

from __future__ import annotations

import json

import numpy as np

from comanip.cli.command_help import command_help
from comanip.cli.options import add_model_arguments, load_model, reach_of, vector
from comanip.cli.outputs import add_output_arguments, output_dir, point_text, report, write_manifest, write_table


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("replan", help=command_help("replan"), description=__doc__)
    add_model_arguments(parser)
    parser.add_argument("--start", type=vector, help="start state [q; qdot], comma-separated (default: at rest at the "
                                                     "body's home position: the origin for a point mass, the ready pose for the Panda)")
    parser.add_argument("--goal", type=vector, help="goal position (m), comma-separated (default: 0.15 m along x from the "
                                                    "start)")
    parser.add_argument("--width", type=float, help="goal width (m) (default: the preset's)")
    parser.add_argument("--rate", type=float, default=100.0, help="control cycles per second (Hz) (default: %(default)s)")
    parser.add_argument("--iterations", type=int, help="Newton iterations per cycle, ≥ 1 (default: 1; with --budget: as "
                                                       "many as fit, at most this many when given)")
    parser.add_argument("--budget", type=float, help="wall budget per cycle (s), from the measured state to the command: "
                                                     "as many iterations as fit, one at least")
    parser.add_argument("--duration", type=float, help="seconds of the loop (default: 1.5 horizons H·h)")
    parser.add_argument("--jump-at", type=float, help="time (s) at which the goal jumps to --jump-to")
    parser.add_argument("--jump-to", type=vector, help="the goal (m) from --jump-at on, comma-separated")
    parser.add_argument("--no-noise", dest="noise", action="store_false",
                        help="execute the commands exactly (default: with the model's motor noise)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the motor noise (default: %(default)s)")
    add_output_arguments(parser, "out/replan")
    parser.add_argument("--png", action="store_true", help="also save a figure of the cycle times and the hand's speed")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.execution import Observation, execute_receding_horizon, executed_cost
    from comanip.planning.planner import Planner
    from comanip.planning.replanner import Replanner
    from comanip.planning.solver_options import SolverOptions

    model = load_model(args)
    start, goal, width, period, budget, iterations, jumps, steps = _checked_loop(args, model)
    out = output_dir(args.out, "replan", args.force)

    planner = Planner(model, SolverOptions(compile=True))
    loops = {"real-time": Replanner(planner, iterations=iterations, max_wall_time=budget),
             "converged": Replanner(planner, iterations=None)}
    runs = {name: execute_receding_horizon(loop, start, goal, width, steps=steps, rng=np.random.default_rng(args.seed),
                                           noise=args.noise, period=period, observation=Observation(0.0, 0.0),
                                           goal_jumps=jumps)
            for name, loop in loops.items()}
    fast, converged = runs["real-time"], runs["converged"]
    scale = planner.problem.normaliser(width)
    cost, reference = executed_cost(planner, fast, width), executed_cost(planner, converged, width)

    cycles = 1e3 * fast.replan_times[1:]
    preparations = 1e3 * fast.preparation_times[1:-1]
    numbers = np.column_stack([fast.t[:-1], 1e3 * fast.replan_times, 1e3 * fast.preparation_times, fast.replan_iterations,
                               fast.ee[:-1], fast.ee_speed[:-1], 1e3 * converged.replan_times])
    header = ["t_s", "cycle_ms", "preparation_ms", "iterations", *(f"hand_{a}_m" for a in "xyz"[: model.d]),
              "hand_speed_m_s", "converged_cycle_ms", "status"]
    csv_path = write_table(out / "replan.csv", header, ([*row, status] for row, status in zip(numbers, fast.replan_statuses)))
    final_goal = fast.goals[-1]
    summary = {"model": model.name, "rate_hz": 1.0 / period, "cycles": steps, "iterations_per_cycle": iterations,
               "budget_s": budget, "noise": args.noise, "seed": args.seed, "goal": final_goal.tolist(), "width": width,
               "cycle_ms": _spread(cycles), "preparation_ms": _spread(preparations),
               "converged_cycle_ms": _spread(1e3 * converged.replan_times[1:]),
               "first_plan_ms": 1e3 * float(fast.replan_times[0]),
               "executed_cost_vs_converged_of_J_best": (cost - reference) / scale,
               "final_error_m": float(np.linalg.norm(fast.ee[-1] - final_goal)),
               "converged_final_error_m": float(np.linalg.norm(converged.ee[-1] - final_goal)),
               "hand_end_from_converged_m": float(np.linalg.norm(fast.ee[-1] - converged.ee[-1])),
               "cycles_not_contracting": sum(status == "not_contracting" for status in fast.replan_statuses[1:])}
    json_path = out / "replan.json"
    json_path.write_text(json.dumps(summary, indent=1), encoding="utf-8")
    written = [json_path, csv_path]
    if args.png:
        from comanip.plots.replan_figure import plot_replan

        written.append(plot_replan(fast, converged, out / "replan.png", f"{model.name} at {1.0 / period:g} Hz"))
    write_manifest(out, "replan", written)
    lines = [f"replan ({model.name}, {1.0 / period:g} Hz, {steps} cycles): cycle median {summary['cycle_ms']['median']:.3g} ms, "
             f"p99 {summary['cycle_ms']['p99']:.3g} ms, preparation after the command {summary['preparation_ms']['median']:.3g} ms; "
             f"executed cost {100 * summary['executed_cost_vs_converged_of_J_best']:+.3g} % of |J_best| against the converged "
             f"loop, hand ends {1e3 * summary['final_error_m']:.3g} mm from the goal {point_text(final_goal)} m"]
    report(args, lines, summary, out, written)
    return 0 if summary["final_error_m"] <= width else 1


def _checked_loop(args, model) -> tuple:
    """Every input of the loop checked before the folder is made: (start (nx,), goal (d,) m, width m, period s,
    budget s or None, iterations per cycle or None, goal jumps [(time s, goal (d,) m)], cycles)."""
    from comanip.arguments import as_count, as_nonnegative, as_optional_positive, as_position
    from comanip.planning.planner import reach_inputs

    start, goal = reach_of(model, args.start, args.goal, 0.15)
    start, goal, width = reach_inputs(model, start, goal, args.width)
    period = 1.0 / as_optional_positive("rate", args.rate, "Hz")
    budget = as_optional_positive("budget", args.budget, "s")
    iterations = as_count("iterations", 1 if args.iterations is None and budget is None else args.iterations,
                          optional=True, unit="Newton iterations per cycle")
    duration = model.H * model.h * 1.5 if args.duration is None else as_optional_positive("duration", args.duration, "s")
    if (args.jump_at is None) != (args.jump_to is None):
        raise ValueError("--jump-at and --jump-to go together: the time (s) the goal jumps and where to (m)")
    jumps = [] if args.jump_at is None else \
        [(as_nonnegative("jump_at", args.jump_at, "s"), as_position("jump_to", args.jump_to, model.d))]
    if jumps:
        reach_inputs(model, start, jumps[0][1], width)
    return start, goal, width, period, budget, iterations, jumps, max(1, round(duration / period))


def _spread(milliseconds: np.ndarray) -> dict:
    """Median, p95, p99 and largest of cycle times (ms); NaN for none."""
    if not len(milliseconds):
        return {"median": float("nan"), "p95": float("nan"), "p99": float("nan"), "largest": float("nan")}
    return {"median": float(np.median(milliseconds)), "p95": float(np.percentile(milliseconds, 95)),
            "p99": float(np.percentile(milliseconds, 99)), "largest": float(np.max(milliseconds))}
