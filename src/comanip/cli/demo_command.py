"""``comanip demo``: the main job on built-in defaults. Plans a reach, predicts a recorded person's goal online as
their hand moves, and runs a simulated Panda beside that person in the synchronisation scenario, the robot
leading the height along its online estimate of their goal. Writes figures (plan.png, online_prediction.png,
sync.png), the numbers (demo.json), the sync trial's CSV and report.md, which says what to look at.

The recorded person is a mouse movement of the ``cursory`` data (the 'data' extra), scaled to an arm's reach;
the robot needs the 'sim' extra: pip install 'comanip[sim,data]'."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from comanip.cli.command_help import command_help
from comanip.cli.outputs import add_output_arguments, output_dir, report, write_manifest
from comanip.extras import missing


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("demo", help=command_help("demo"), description=__doc__,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seed", type=int, default=0, help="which recorded person (default: %(default)s)")
    add_output_arguments(parser, "out/demo")
    parser.set_defaults(func=run)


def run(args) -> int:
    for extra in ("data", "sim"):
        if (absent := missing(extra)) is not None:
            raise absent
    if isinstance(args.seed, bool) or args.seed < 0:
        raise ValueError(f"--seed must be an integer ≥ 0, got {args.seed}")
    from comanip import demo
    from comanip.cli.simulate_command import write_outputs
    from comanip.plots.demo_figure import plot_online_prediction
    from comanip.plots.plan_figure import plot_plan

    out = output_dir(args.out, "demo", args.force)
    seconds = {}
    begin = time.perf_counter()
    plan = demo.plan_reach()
    seconds["plan"] = time.perf_counter() - begin
    files = [plot_plan(plan, out / "plan.png", title=f"step 1: a planned reach of the planar model ({plan.status})")]

    begin = time.perf_counter()
    sync = demo.run_sync_beside(args.seed)
    seconds["sync"] = time.perf_counter() - begin
    recording = sync.setup.recording(args.seed)
    begin = time.perf_counter()
    prediction = demo.predict_online(recording)
    seconds["online"] = time.perf_counter() - begin
    files.append(plot_online_prediction(prediction, out / "online_prediction.png"))
    sync_files, _ = write_outputs(sync, out, frames=False)
    files += sync_files

    trial = sync.goals[demo.SYNC_GOAL].trials[0]
    numbers = _numbers(plan, prediction, trial, seconds)
    files.append(_write_json(numbers, out / "demo.json"))
    files.append(_write_report(numbers, out / "report.md"))
    write_manifest(out, "demo", files)
    online = numbers["online_prediction"]
    lines = [f"plan: {plan.status}, the planar model's reach to {list(demo.PLAN_GOAL)} m in {1e3 * plan.solve_time:.0f} ms",
             f"online prediction of {recording.name}: goal {100 * online['error_m'][0.4]:.1f} cm off at 40 % of the movement, "
             f"{100 * online['error_m'][1.0]:.1f} cm at its end ({online['updates']} updates)",
             f"robot beside the person ({demo.SYNC_POLICY} policy): goal estimate {100 * numbers['sync']['goal_error_final_m']:.1f} cm off, "
             f"handle {100 * numbers['sync']['final_error_m']:.1f} cm from the goal at the end",
             f"what to look at: {out / 'report.md'}"]
    report(args, lines, numbers, out, files)
    return 0


def _numbers(plan, prediction, trial, seconds: dict) -> dict:
    from comanip import demo

    recording = prediction.recording
    metrics = trial.metrics
    sync_keys = ("goal_error_final_m", "goal_error_50pct_m", "final_error_m", "movement_time_s", "peak_force_N", "rms_force_N",
                 "sync_lag_s", "person_work_J", "work_against_robot_J")
    return {
        "plan": {"model": plan.model_name, "goal_m": list(demo.PLAN_GOAL), "status": plan.status, "success": bool(plan.success),
                 "final_error_m": float(plan.final_error), "peak_speed_m_per_s": float(np.max(plan.ee_speed)),
                 "solve_time_s": float(plan.solve_time)},
        "online_prediction": {"recording": recording.name, "distance_m": recording.distance,
                              "movement_time_s": recording.movement_time, "updates": int(len(prediction.t)),
                              "error_m": {f: prediction.error_at(f) for f in demo.FRACTIONS},
                              "final_status": prediction.status[-1] if prediction.status else None},
        "sync": {"policy": demo.SYNC_POLICY, "goal_m": [float(v) for v in trial.record.goal]}
        | {key: float(metrics[key]) for key in sync_keys if key in metrics},
        "wall_time_s": {key: round(value, 2) for key, value in seconds.items()},
    }


def _write_json(numbers: dict, path: Path) -> Path:
    path.write_text(json.dumps(numbers, indent=1, default=float))
    return path


def _write_report(numbers: dict, path: Path) -> Path:
    plan, online, sync = numbers["plan"], numbers["online_prediction"], numbers["sync"]
    errors = " · ".join(f"{int(100 * f)} %: {100 * e:.1f} cm" for f, e in online["error_m"].items())
    path.write_text(f"""# comanip demo

## 1. A planned reach — `plan.png`
The planar model's reach from rest to {plan['goal_m']} m: `{plan['status']}`, ending {1e3 * plan['final_error_m']:.1f} mm
from the goal, solved in {1e3 * plan['solve_time_s']:.0f} ms. Look at the bell-shaped speed profile and at the spread of the
hand, which grows during the fast part of the reach and shrinks again as the hand closes in on the goal.

## 2. A recorded person's goal, predicted as their hand moves — `online_prediction.png`
The recorded movement `{online['recording']}` ({100 * online['distance_m']:.0f} cm in {online['movement_time_s']:.2f} s) was fed
to the online estimator sample by sample ({online['updates']} updates). Distance of the predicted goal from where the
person aimed, by the fraction of the movement seen: {errors}. Look at how early the coloured dots settle near
the red star, and at the error curve against its 2σ band: the estimate should be as uncertain as it is wrong.
The last update's status is `{online['final_status']}`.

## 3. The robot beside the same person — `sync.png`
A simulated Panda carries an object with a person whose hand follows the same recording (turned onto a reach to
{[round(v, 2) for v in sync['goal_m']]} m); the person leads x–y, the robot leads the height along its online estimate of the
person's goal (`{sync['policy']}` policy). At the end its goal estimate is {100 * sync['goal_error_final_m']:.1f} cm off and the
handle {100 * sync['final_error_m']:.1f} cm from the goal; the peak force between person and handle is
{sync['peak_force_N']:.0f} N (RMS {sync['rms_force_N']:.0f} N). Look at how closely the robot's height follows the person's progress
and at the interaction force: a robot that predicts the goal well makes the person push less.

`demo.json` holds these numbers; `sync_near_*.csv` the trial's samples. `comanip simulate sync --policy all` compares
the robot policies over more trials; `comanip validate` compares the model with the paper's analyses.
""")
    return path
