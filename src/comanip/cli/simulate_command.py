"""``comanip simulate sync|handover``: the paper's collaborative scenarios (Section VI) with a simulated Panda
under impedance control and a simulated person, in MuJoCo. Writes a figure, one CSV per trial, a summary
JSON and (where offscreen rendering works) a frame strip per goal. For sync, ``--policy NAME|all`` chooses
the robot (default: the paper's one-shot estimate) and writes a table (CSV and markdown, median and IQR
over trials) and figures comparing the policies over the same trials and person seeds (their measures; the
person's x–y and the robot's z speed over t / MT), ``--person-leads-height`` makes the person intend the height too
(default: the paper's task, the height the robot's), and ``--person``
chooses the person (default: the model's own): ``model``, ``recorded`` (a recorded mouse movement), ``arm`` (a
recorded arm reach of examples/data/arm_reaches), or a folder of your own arm reaches (the TAT-HUM layout, or
Vicon Nexus exports: one person's folder or a folder of people's), each optionally with ``-xP`` to play it P times
slower (``arm-x2.5``) or faster (``model-x0.7``); ``--carry-calibration`` lets the estimating robots keep what they
learned of the person from trial to trial."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from comanip.cli.command_help import command_help
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
    parser.add_argument("--policy", help="sync only: the robot policy, one of passive, admittance, prior-only, "
                                         "constant-velocity, onset-minimum-jerk, minimum-jerk, one-shot (default), "
                                         "continuous, forecast, or all of them")
    parser.add_argument("--person-leads-height", action="store_true",
                        help="sync only: the person intends the height too (default: the paper's task, the person "
                             "leads x–y and follows the height the robot leads)")
    parser.add_argument("--carry-calibration", action="store_true",
                        help="sync only: the continuous and forecast robots keep what they learned of the person "
                             "(amplitude, pace, spread) from trial to trial, in seed order (default: every trial's "
                             "robot meets a person not seen yet)")
    parser.add_argument("--trigger", help="handover only: what releases the robot, goal_distance (default: the handle "
                                          "within T of the known goal) or estimate (within T of the online goal estimate)")
    parser.add_argument("--person", help="sync only: who holds the handle, model (default: the reaching model's "
                                         "person), recorded (a recorded mouse movement, the 'data' extra), arm (a "
                                         "recorded arm reach of examples/data/arm_reaches) or FOLDER (your own arm "
                                         "reaches: TAT-HUM layout, or Vicon Nexus exports, one person's folder such "
                                         "as ue_adl/ADL003 or a folder of people's); add -xP to play it P times as "
                                         "long, e.g. arm-x2.5; the trial with seed s plays recording 37·s mod N of "
                                         "the N that play as a reach")
    add_output_arguments(parser, "out/simulate")
    parser.add_argument("--no-frames", action="store_true", help="skip the rendered frame strip")
    parser.add_argument("--viewer", action="store_true", help="replay the first trial in MuJoCo's viewer (needs a display)")
    parser.set_defaults(func=run)


def run(args) -> int:
    from comanip.simulation.report import write_summary
    from comanip.simulation.scenario_runs import run_scenario

    choice = scenario_settings(args)    # every setting checked before any solver or model is built
    out = output_dir(args.out, "simulate", args.force)
    result = run_scenario(args.scenario, choice.settings_by_goal, choice.policies, arm_reaches=choice.arm_reaches)
    files, strips = write_outputs(result, out, frames=not args.no_frames)
    summary = result.summary()
    summary_path = out / f"{args.scenario}_summary.json"
    files.append(summary_path)
    write_summary(summary_path, summary | {"frame_strips": strips, "files": [str(p) for p in files]})
    if args.viewer:
        from comanip.simulation.rendering import replay_in_viewer

        record = next(iter(result.goals.values())).trials[0].record
        print(replay_in_viewer(result.setup.world.model, record.t, record.qpos))
    write_manifest(out, "simulate", files)
    lines, full = _report_text(result, summary, out)
    report(args, lines, full, out, files)
    return 0


@dataclass(frozen=True)
class ScenarioChoice:
    """What the command line chose: each goal's settings, the compared policies and the arm people's folder."""

    settings_by_goal: dict
    """{goal label: settings}."""
    policies: list[str] | None
    """The compared robot policies (None: the settings' own only)."""
    arm_reaches: Path | None
    """The TAT-HUM folder an arm person plays (None: the person is not an arm)."""


def scenario_settings(args) -> ScenarioChoice:
    """What the arguments choose, every argument checked (one-line ValueError)."""
    from comanip.simulation import resolve_goal, scenario
    from comanip.simulation.people import choose_person
    from comanip.simulation.policies import POLICIES, check_policy

    settings_class, _ = scenario(args.scenario)
    common = {"trials": args.trials, "width": args.width, "kappa": args.kappa, "seed": args.seed, "duration": args.duration}
    policies, arm_reaches = None, None
    if args.policy is not None:
        if args.scenario != "sync":
            raise ValueError(f"--policy applies to the sync scenario only, got scenario {args.scenario!r}")
        policies = list(POLICIES) if args.policy == "all" else [check_policy(args.policy)]
        common["policy"] = "one-shot" if "one-shot" in policies else policies[0]
    if args.trigger is not None:
        if args.scenario != "handover":
            raise ValueError(f"--trigger applies to the handover scenario only, got scenario {args.scenario!r}")
        common["release_trigger"] = args.trigger
    if args.person_leads_height:
        if args.scenario != "sync":
            raise ValueError(f"--person-leads-height applies to the sync scenario only, got scenario {args.scenario!r}")
        common["person_leads_height"] = True
    if args.carry_calibration:
        if args.scenario != "sync":
            raise ValueError(f"--carry-calibration applies to the sync scenario only, got scenario {args.scenario!r}")
        common["carry_calibration"] = True
    if args.person is not None:
        if args.scenario != "sync":
            raise ValueError(f"--person applies to the sync scenario only, got scenario {args.scenario!r}")
        person = choose_person(args.person)
        common["person"], arm_reaches = person.parameters, person.arm_reaches
    settings = {_label(goal): settings_class(goal=tuple(resolve_goal(goal)), **common) for goal in args.goal or ["near", "far"]}
    return ScenarioChoice(settings, policies, arm_reaches)


def write_outputs(result, out: Path, frames: bool) -> tuple[list[Path], dict]:
    """Write the policy comparison (table and figure, the other policies' trials), one CSV per trial, a frame
    strip per goal (when ``frames``) and the scenario's figure; the files written and {goal label: strip path
    or why there is none}."""
    from comanip.simulation.report import write_trials

    files, strips = _write_policy_comparison(result, out), {}
    for label, goal in result.goals.items():
        stem = f"{result.scenario}_{label}"
        files += write_trials([trial.record for trial in goal.trials], out, stem)
        if frames:
            from comanip.simulation.rendering import frame_strip

            record = goal.trials[0].record
            path, reason = frame_strip(result.setup.settings.object_mass, record.qpos, out / f"{stem}_frames.png",
                                       markers=[record.goal])
            strips[label] = str(path) if path else reason
            files += [path] if path else []
    return files + FIGURES[result.scenario](result, out), strips


def _write_policy_comparison(result, out: Path) -> list[Path]:
    """The comparison table (CSV and markdown), its figure and the trials of the policies other than the
    settings' own; nothing when no policies were compared."""
    if not result.policies:
        return []
    from comanip.plots.policy_comparison_figure import plot_policy_comparison
    from comanip.plots.sync_speed_profiles import plot_speed_profiles
    from comanip.simulation.policy_comparison import write_comparison
    from comanip.simulation.report import write_trials

    files = write_comparison(result.policy_rows(), out / "sync_policies")
    files.append(plot_policy_comparison(result.policy_trials(), out / "sync_policies.png"))
    files.append(plot_speed_profiles(result.policy_trials(), out / "sync_speed_profiles.png"))
    for label, goal in result.goals.items():
        files += [path for name, trials in goal.policies.items() if name != goal.settings.policy
                  for path in write_trials([trial.record for trial in trials], out, f"sync_{label}_{name}")]
    return files


def _sync_figure(result, out: Path) -> list[Path]:
    from comanip.plots.simulation_sync import plot_sync

    runs = {label: goal.trials for label, goal in result.goals.items()}
    return [plot_sync(runs, result.settings.observation_time, out / "sync.png")]


def _handover_figure(result, out: Path) -> list[Path]:
    """The handover figure of the goals with profiles (≥ 2 trials); none without any."""
    from comanip.plots.simulation_handover import plot_handover

    runs = {label: goal.profiles for label, goal in result.goals.items() if goal.profiles is not None}
    return [plot_handover(runs, out / "handover.png")] if runs else []


FIGURES = {"sync": _sync_figure, "handover": _handover_figure}
"""scenario name -> its figure"""


def _report_text(result, summary: dict, out: Path) -> tuple[list[str], object]:
    """The terminal lines and what --verbose prints (the comparison table first, when policies were compared)."""
    goals = summary["goals"]
    full = {label: {"summary": _headline(goals[label]["summary"]), "timing": goals[label]["timing"]} for label in goals}
    compared = "" if result.policies is None else f" x {len(result.policies)} policies"
    lines = [f"simulate {result.scenario}, goal {label}: {goal.settings.trials} trials{compared} in "
             f"{goal.timing['wall_s']:.1f} s ({goal.timing['real_time_factor']:.1f}x real time)"
             for label, goal in result.goals.items()]
    if result.policies:
        lines.append(f"policy comparison (median [q25, q75]) in {out / 'sync_policies.md'}")
        full = (out / "sync_policies.md").read_text() + "\n" + json.dumps(full, indent=1, default=float)
    return lines, full


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
