"""``comanip simulate sync|handover``: the paper's collaborative scenarios (Section VI) with a simulated Panda
under impedance control and a simulated person, in MuJoCo. Writes a figure, one CSV per trial, a summary
JSON and (where offscreen rendering works) a frame strip per goal. For sync, ``--policy NAME|all`` chooses
the robot (default: the paper's one-shot estimate) and writes a table (CSV and markdown, median and IQR
over trials) and a figure comparing the policies over the same trials and person seeds."""

from __future__ import annotations

import json
import time

from comanip.cli.commands import command_help
from comanip.cli.outputs import add_output_arguments, output_dir, report, write_manifest


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("simulate", help=command_help("simulate"), description=__doc__)
    parser.add_argument("scenario", help="sync (paper VI-A) or handover (paper VI-B)")
    parser.add_argument("--trials", type=int, default=5, help="trials per goal, each with its own seed (default: %(default)s)")
    parser.add_argument("--goal", action="append",
                        help="the person's goal: near, far or x,y,z in m (robot base frame); repeat for several "
                             "(default: near and far)")
    parser.add_argument("--width", type=float, help="the person's goal width (m) (default: the Cartesian preset's)")
    parser.add_argument("--kappa", type=float, help="the person's motor-noise variance (default: the preset's)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first trial (default: %(default)s)")
    parser.add_argument("--duration", type=float, help="simulated seconds per trial (default: the preset's horizon)")
    parser.add_argument("--policy", help="sync only: the robot policy, one of passive, prior-only, constant-velocity, "
                                         "minimum-jerk, one-shot (default), continuous, or all of them")
    parser.add_argument("--trigger", help="handover only: what releases the robot, goal_distance (default: the handle "
                                          "within T of the known goal) or estimate (within T of the online goal estimate)")
    add_output_arguments(parser, "out/simulate")
    parser.add_argument("--no-frames", action="store_true", help="skip the rendered frame strip")
    parser.add_argument("--viewer", action="store_true", help="replay the first trial in MuJoCo's viewer (needs a display)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.simulation import SCENARIOS, ScenarioSetup, resolve_goal, scenario

    from comanip.simulation.policies import POLICIES, check_policy

    settings_class, runner = scenario(args.scenario)
    goals = args.goal or ["near", "far"]
    common = {"trials": args.trials, "width": args.width, "kappa": args.kappa, "seed": args.seed, "duration": args.duration}
    policies = None
    if args.policy is not None:
        if args.scenario != "sync":
            raise ValueError(f"--policy applies to the sync scenario only, got scenario {args.scenario!r}")
        policies = list(POLICIES) if args.policy == "all" else [check_policy(args.policy)]
        common["policy"] = "one-shot" if "one-shot" in policies else policies[0]
    if args.trigger is not None:
        if args.scenario != "handover":
            raise ValueError(f"--trigger applies to the handover scenario only, got scenario {args.scenario!r}")
        common["release_trigger"] = args.trigger
    # every setting is checked here, before any solver or model is built
    all_settings = {_label(goal): settings_class(goal=tuple(resolve_goal(goal)), **common) for goal in goals}
    setup = ScenarioSetup(next(iter(all_settings.values())))
    out = output_dir(args.out, "simulate", args.force)

    results, timing, by_policy = {}, {}, {}
    for label, settings in all_settings.items():
        begin = time.perf_counter()
        if policies is None:
            results[label] = runner(settings, setup)
        else:
            from comanip.simulation.policy_comparison import compare_sync_policies

            by_policy[label] = compare_sync_policies({label: settings}, policies, setup, progress=True)[label]
            results[label] = by_policy[label][settings.policy]
        wall = time.perf_counter() - begin
        simulated = settings.trials * setup.duration * (1 if policies is None else len(policies))
        timing[label] = {"wall_s": wall, "simulated_s": simulated, "real_time_factor": simulated / wall}

    from comanip.simulation.report import settings_dict, summarise, write_summary, write_trials

    files, goals_out, strips = [], {}, {}
    if by_policy:
        from comanip.plots.policy_comparison_figure import plot_policy_comparison
        from comanip.simulation.policy_comparison import comparison_rows, write_comparison

        rows = comparison_rows(by_policy)
        files += write_comparison(rows, out / "sync_policies")
        files.append(plot_policy_comparison(by_policy, out / "sync_policies.png"))
        for label, runs in by_policy.items():
            for name, trials in runs.items():
                if name != all_settings[label].policy:
                    files += write_trials([trial.record for trial in trials], out, f"sync_{label}_{name}")
    for label, result in results.items():
        trials = result if args.scenario == "sync" else result.trials
        stem = f"{args.scenario}_{label}"
        files += write_trials([trial.record for trial in trials], out, stem)
        metrics = [trial.metrics for trial in trials]
        goals_out[label] = {"goal_m": list(all_settings[label].goal), "trials": metrics, "summary": summarise(metrics),
                            "timing": timing[label]}
        if args.scenario == "handover":
            goals_out[label]["schedule"] = result.schedule.summary()
            if result.dispersion is not None:
                # the lead at 400 N/m holds the spread down until the release, so this peak lies inside T by
                # construction; the person's own transition is measured with a passive robot
                # (studies/does_the_predicted_handover_match_the_person/measure_handover_transition.py)
                goals_out[label]["transition"] = {
                    "predicted_distance_m": result.schedule.transition_distance,
                    "handover_spread_peak_distance_m": result.dispersion.transition_distance}
        if label in by_policy:
            goals_out[label]["policies"] = {name: summarise([trial.metrics for trial in trials])
                                            for name, trials in by_policy[label].items()}
        if not args.no_frames:
            from comanip.simulation.rendering import frame_strip

            path, reason = frame_strip(setup.settings.object_mass, trials[0].record.qpos, out / f"{stem}_frames.png",
                                       markers=[trials[0].record.goal])
            strips[label] = str(path) if path else reason
            files += [path] if path else []
    if args.scenario == "sync":
        from comanip.plots.simulation_sync import plot_sync

        files.append(plot_sync(results, next(iter(all_settings.values())).observation_time, out / "sync.png"))
    elif any(run.dispersion is not None for run in results.values()):     # the profiles need ≥ 2 trials
        from comanip.plots.simulation_handover import plot_handover

        files.append(plot_handover({k: r for k, r in results.items() if r.dispersion is not None}, out / "handover.png"))
    summary_path = out / f"{args.scenario}_summary.json"
    files.append(summary_path)
    write_summary(summary_path, {"scenario": args.scenario, "scenarios_available": sorted(SCENARIOS),
                                 "settings": settings_dict(next(iter(all_settings.values()))), "goals": goals_out,
                                 "frame_strips": strips,
                                 "files": [str(p) for p in files]})
    if args.viewer:
        from comanip.simulation.rendering import replay_in_viewer

        first = next(iter(results.values()))
        record = (first if args.scenario == "sync" else first.trials)[0].record
        print(replay_in_viewer(setup.world.model, record.t, record.qpos))
    write_manifest(out, "simulate", files)
    full = {label: {"summary": _headline(goals_out[label]["summary"]), "timing": timing[label]} for label in goals_out}
    lines = [f"simulate {args.scenario}, goal {label}: {all_settings[label].trials} trials"
             f"{'' if policies is None else f' x {len(policies)} policies'} in {timing[label]['wall_s']:.1f} s "
             f"({timing[label]['real_time_factor']:.1f}x real time)" for label in goals_out]
    if by_policy:
        lines.append(f"policy comparison (median [q25, q75]) in {out / 'sync_policies.md'}")
        full = (out / "sync_policies.md").read_text() + "\n" + json.dumps(full, indent=1, default=float)
    report(args, lines, full, out, files)
    return 0


def _label(goal: str) -> str:
    """A file-name-safe label of a goal argument: the name, or x_y_z in mm."""
    from comanip.simulation import NAMED_GOALS, resolve_goal

    if goal in NAMED_GOALS:
        return goal
    return "_".join(str(int(round(1e3 * v))) for v in resolve_goal(goal))


def _headline(summary: dict) -> dict:
    """Means (or fractions) of the summary, rounded, for the terminal."""
    return {k: (round(v["mean"], 4) if v.get("mean") is not None else v.get("fraction")) for k, v in summary.items()
            if "mean" in v or "fraction" in v}
