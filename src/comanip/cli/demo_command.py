"""``comanip demo``: the main job on built-in defaults. Plans a reach, predicts a recorded person's goal online as
their hand moves, and runs a simulated Panda beside a person guiding the handle in the synchronisation scenario,
the robot leading the height along its online estimate of their goal. Writes figures (plan.png,
online_prediction.png, co_manipulation.png), the numbers (demo.json), the series the last figure draws
(co_manipulation.csv, forecasts.csv), the sync trial's samples and report.md, which says what to look at.

Step 2's person is a mouse movement of the ``cursory`` data (the 'data' extra), scaled to an arm's reach; step 3's
a recorded arm reach of examples/data/arm_reaches played 2.5 times slower, as a person moves a heavy handle; the
robot needs the 'sim' extra: pip install 'comanip[sim,data]'."""

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
    parser.add_argument("--seed", type=int, default=0, help="which recorded people: step 2's mouse movement and step "
                                                         "3's arm reach (default: %(default)s)")
    add_output_arguments(parser, "out/demo")
    parser.set_defaults(func=run)


def run(args) -> int:
    for extra in ("data", "sim"):
        if (absent := missing(extra)) is not None:
            raise absent
    if isinstance(args.seed, bool) or args.seed < 0:
        raise ValueError(f"--seed must be an integer ≥ 0, got {args.seed}")
    from comanip import demo
    from comanip.plots.demo_figure import plot_co_manipulation, plot_online_prediction
    from comanip.plots.plan_figure import plot_plan
    from comanip.simulation.people import shipped_arm_reaches
    from comanip.simulation.report import write_trials

    shipped_arm_reaches()            # step 3's person: a one-line error before any work when they are absent
    out = output_dir(args.out, "demo", args.force)
    seconds = {}
    begin = time.perf_counter()
    plan = demo.plan_reach()
    seconds["plan"] = time.perf_counter() - begin
    files = [plot_plan(plan, out / "plan.png", title=f"step 1: a planned reach of the planar model ({plan.status})")]

    begin = time.perf_counter()
    sync = demo.run_sync_beside(args.seed)
    forecasts = demo.robot_forecasts(sync)
    seconds["sync"] = time.perf_counter() - begin
    begin = time.perf_counter()
    prediction = demo.predict_online(sync.setup.recording(args.seed))
    seconds["online"] = time.perf_counter() - begin
    files.append(plot_online_prediction(prediction, out / "online_prediction.png"))

    trial = sync.goals[demo.SYNC_GOAL].trials[0]
    arm = sync.setup.recording(args.seed, "recorded-arm")
    files += write_trials([trial.record], out, f"sync_{demo.SYNC_GOAL}")
    files += [_write_series(trial.record, out / "co_manipulation.csv"), _write_forecasts(forecasts, out / "forecasts.csv")]
    files.append(plot_co_manipulation(trial.record, forecasts, sync.settings.observation_time, trial.metrics["movement_time_s"],
                                      demo.GUIDING_FORCE_N, demo.QUANTITIES, out / "co_manipulation.png",
                                      title=f"step 3: the robot beside a person guiding the handle (arm reach {arm.name}, "
                                            f"{demo.SYNC_PERSON}; {demo.SYNC_POLICY} policy)"))
    numbers = _numbers(plan, prediction, trial, arm, forecasts, sync.settings.observation_time, seconds)
    files.append(_write_json(numbers, out / "demo.json"))
    files.append(_write_report(numbers, out / "report.md"))
    write_manifest(out, "demo", files)
    online, step3 = numbers["online_prediction"], numbers["sync"]
    lines = [f"plan: {plan.status}, the planar model's reach to {list(demo.PLAN_GOAL)} m in {1e3 * plan.solve_time:.0f} ms",
             f"online prediction of {prediction.recording.name}: goal {100 * online['error_m'][0.4]:.1f} cm off at 40 % of the movement, "
             f"{100 * online['error_m'][1.0]:.1f} cm at its end ({online['updates']} updates)",
             f"robot beside a person guiding the handle ({step3['person']}, {demo.SYNC_POLICY} policy): force beyond holding "
             f"{step3['peak_force_change_N']:.0f} N at its peak, goal estimate {1e3 * step3['goal_error_final_m']:.1f} mm off at the end",
             f"what to look at: {out / 'report.md'}"]
    report(args, lines, numbers, out, files)
    return 0


SERIES_COLUMNS = ("t_s", "force_N", "force_change_N", "goal_estimate_error_m")
"""Columns of co_manipulation.csv: time (s), |F| and |F - F(0)| of the person's force on the handle (N), and the
distance of the robot's goal estimate from the person's goal (m; empty before the first estimate)."""
FORECAST_COLUMNS = ("made_at_s", "t_s", "forecast_x_m", "forecast_y_m", "forecast_z_m", "hand_x_m", "hand_y_m", "hand_z_m",
                    "error_m")
"""Columns of forecasts.csv: when the forecast was made (s), the time it forecasts (s), the forecast hand and the
hand (m) and their distance (m)."""


def _write_series(record, path: Path) -> Path:
    """The series of the force and goal-estimate panels, every sample."""
    force = record.person_force
    columns = [record.t, np.linalg.norm(force, axis=1), np.linalg.norm(force - force[0], axis=1),
               np.linalg.norm(record.goal_estimate - record.goal, axis=1)]
    np.savetxt(path, np.column_stack(columns), delimiter=",", header=",".join(SERIES_COLUMNS), comments="", fmt="%.9g")
    return path


def _write_forecasts(forecasts, path: Path) -> Path:
    """The forecasts of the path panels, one row per forecast and time."""
    rows = [np.column_stack([np.full(len(f.t), f.made_at), f.t, f.position, f.hand, f.error]) for f in forecasts]
    np.savetxt(path, np.vstack(rows), delimiter=",", header=",".join(FORECAST_COLUMNS), comments="", fmt="%.9g")
    return path


def _numbers(plan, prediction, trial, arm, forecasts, observation_time: float, seconds: dict) -> dict:
    from comanip import demo

    recording = prediction.recording
    metrics = trial.metrics
    sync_keys = ("goal_error_final_m", "goal_error_50pct_m", "final_error_m", "movement_time_s", "peak_speed_m_per_s",
                 "peak_force_N", "rms_force_N", "peak_force_change_N", "rms_force_change_N", "sync_lag_s",
                 "person_work_J", "work_against_robot_J", "arrival_lag_mt", "peak_lag_mt", "height_error_at_arrival_m")
    movement_time = metrics["movement_time_s"]
    return {
        "plan": {"model": plan.model_name, "goal_m": list(demo.PLAN_GOAL), "status": plan.status, "success": bool(plan.success),
                 "final_error_m": float(plan.final_error), "peak_speed_m_per_s": float(np.max(plan.ee_speed)),
                 "solve_time_s": float(plan.solve_time)},
        "online_prediction": {"recording": recording.name, "distance_m": recording.distance,
                              "movement_time_s": recording.movement_time, "updates": int(len(prediction.t)),
                              "error_m": {f: prediction.error_at(f) for f in demo.FRACTIONS},
                              "final_status": prediction.status[-1] if prediction.status else None},
        "sync": {"policy": demo.SYNC_POLICY, "person": demo.SYNC_PERSON, "recording": arm.name,
                 "recorded_movement_time_s": arm.movement_time, "recorded_distance_m": arm.distance,
                 "goal_m": [float(v) for v in trial.record.goal], "observation_time_s": observation_time,
                 "holding_force_N": float(np.linalg.norm(trial.record.person_force[0])),
                 "guiding_force_N": list(demo.GUIDING_FORCE_N),
                 "forecasts": [{"made_at_s": f.made_at, "fraction_of_movement": f.made_at / movement_time,
                                "goal_error_m": float(np.linalg.norm(f.goal - trial.record.goal)),
                                "rms_path_error_m": f.rms_error, "max_path_error_m": float(f.error.max())} for f in forecasts]}
        | {key: float(metrics[key]) for key in sync_keys if key in metrics},
        "wall_time_s": {key: round(value, 2) for key, value in seconds.items()},
    }


def _write_json(numbers: dict, path: Path) -> Path:
    path.write_text(json.dumps(numbers, indent=1, default=float))
    return path


def _write_report(numbers: dict, path: Path) -> Path:
    from comanip.demo import QUANTITIES, against_range

    plan, online, sync = numbers["plan"], numbers["online_prediction"], numbers["sync"]
    errors = " · ".join(f"{int(100 * f)} %: {100 * e:.1f} cm" for f, e in online["error_m"].items())
    low, high = sync["guiding_force_N"]
    forecasts = "; ".join(f"made at {f['made_at_s']:.2f} s ({100 * f['fraction_of_movement']:.0f} % of the movement): "
                          f"{100 * f['rms_path_error_m']:.1f} cm RMS, at most {100 * f['max_path_error_m']:.1f} cm, its goal "
                          f"{100 * f['goal_error_m']:.1f} cm off" for f in sync["forecasts"])
    path.write_text(f"""# comanip demo

## 1. A planned reach — `plan.png`
The planar model's reach from rest to {plan['goal_m']} m: `{plan['status']}`, ending {1e3 * plan['final_error_m']:.1f} mm
from the goal, solved in {1e3 * plan['solve_time_s']:.0f} ms. Look at the bell-shaped speed profile and at the spread of the
hand, which grows during the fast part of the reach and shrinks again as the hand closes in on the goal.

## 2. A recorded person's goal, predicted as their hand moves — `online_prediction.png`
The recorded mouse movement `{online['recording']}` ({100 * online['distance_m']:.0f} cm in {online['movement_time_s']:.2f} s)
was fed to the online estimator sample by sample ({online['updates']} updates). Distance of the predicted goal from where
the person aimed, by the fraction of the movement seen: {errors}. Look at how early the coloured dots settle near
the red star, and at the error curve against its 2σ band: the estimate should be as uncertain as it is wrong.
The last update's status is `{online['final_status']}`. This step plays a mouse movement because its recording holds
the target the person aimed at; the arm reaches of step 3 say only which of two targets, so there the goal is
where the person's reach takes the handle.

## 3. The robot beside a person guiding the handle — `co_manipulation.png`
A simulated Panda and a person carry a 1.5 kg object by its handle, whose apparent mass is 7–16 kg per axis (the
arm's inertia at the handle and the object). The person's hand follows the recorded arm reach `{sync['recording']}`
({100 * sync['recorded_distance_m']:.0f} cm in {sync['recorded_movement_time_s']:.2f} s, a fingertip pointing at a target),
scaled and turned onto a reach to {[round(v, 2) for v in sync['goal_m']]} m and played 2.5 times slower (`{sync['person']}`):
people move a heavy handle more slowly than a fingertip, and at the recorded pace the handle's inertia alone
would take 6 times the force. The handle's movement takes {sync['movement_time_s']:.2f} s, at up to
{sync['peak_speed_m_per_s']:.2f} m/s. This is the paper's synchronisation task: the person leads x–y and leaves the height to
the robot, their arm following it; from t_o = {sync['observation_time_s']:.1f} s the robot leads the height along its online
estimate of the person's goal (`{sync['policy']}` policy), to arrive in step with them. The height arrives
{sync['arrival_lag_mt']:+.3f} MT after the person's horizontal arrival (over the movement time; negative: before), its speed
peaks {sync['peak_lag_mt']:+.3f} MT after theirs, and when the person arrives the height is
{1e3 * sync['height_error_at_arrival_m']:.1f} mm from the table (in step would be within 0.05 MT and 5 mm). The figure shows
what this section names:

- **{QUANTITIES['goal']}** (top left): at the end of the trial the goal estimate is {1e3 * sync['goal_error_final_m']:.1f} mm
  from the person's goal, at half the movement {100 * sync['goal_error_50pct_m']:.1f} cm; the handle ends
  {1e3 * sync['final_error_m']:.1f} mm from the goal.
- **{QUANTITIES['path']}** (bottom): the robot's forecast of where the hand goes from the moment it is made (not
  the goal at the end, above), against where the hand went until the movement ends: {forecasts}.
- **{QUANTITIES['force']}** (top right), from t_o on: the person holds the object's weight, which this robot leaves
  to them ({sync['holding_force_N']:.1f} N at rest); the force beyond that peaks at {sync['peak_force_change_N']:.1f} N (RMS
  {sync['rms_force_change_N']:.1f} N), {against_range(sync['peak_force_change_N'], (low, high))} the {low:.0f}–{high:.0f} N people apply to guide a
  partner through a held contact (Sawers et al. 2017); the whole force peaks at {sync['peak_force_N']:.1f} N (RMS
  {sync['rms_force_N']:.1f} N), {against_range(sync['peak_force_N'], (low, high))} that range. Above the weight, the person's force
  accelerates and brakes the handle and, where the robot moves the height, follows it with a relaxed arm.

Look at how the forecasts close in on the hand's path as the reach goes on while the goal estimate settles, and at
when the force peaks against the green band of what people apply.

`demo.json` holds these numbers; `co_manipulation.csv` and `forecasts.csv` the series the figure draws;
`sync_near_trial0.csv` the trial's samples. `comanip simulate sync --person {sync['person']} --policy all` compares the
robot policies over more trials with such people; `comanip validate` compares the model with the paper's analyses.
""")
    return path
