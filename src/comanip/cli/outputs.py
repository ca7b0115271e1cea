"""Output folders of the subcommands: each command has its own default folder (``out/<command>``), a folder
holding another command's results is written into only with ``--force``, and every folder gets a
``manifest.json`` saying which command wrote it, when, and what each file is.

A command run again into its own folder replaces its previous outputs: the files its last run listed in the
manifest and this run does not write are removed, so the manifest lists exactly the files of this run (for
``transition``, whose actions share a folder, of each action's last run). On the terminal a command prints
a short summary and where the files are (:func:`report`); ``--verbose`` prints the full results instead."""

from __future__ import annotations

import argparse
import json
import shlex
import sys
import time
from collections.abc import Sequence
from fnmatch import fnmatch
from pathlib import Path

MANIFEST = "manifest.json"

FILE_KINDS = (
    ("plan.json", "the plan: status, success, objective, times, state and end-effector mean and covariance, torques"),
    ("plan.csv", "the plan, one row per step: t, q, qdot, activation-stage forces (if any), hand position, velocity and std, torque"),
    ("replan.json", "the closed loop replanned at a controller's rate: cycle times, executed cost against the converged loop, final errors"),
    ("replan.csv", "the closed loop, one row per control cycle: its replan and preparation times, iterations, the hand, its status"),
    ("replan.png", "figure: cycle times against the period, and the hand's speed beside the converged loop"),
    ("estimate.json", "the goal estimate: estimated goal ('goal'), status, and the plan through the observation"),
    ("estimate.csv", "the estimate's predicted trajectory, one row per step (columns as a plan CSV)"),
    ("online.csv", "the stream through the online estimator, one row per sample: reach, goal, its spread, the forecast ahead"),
    ("online.png", "figure: the hand's path with the goal estimated at each sample, and both over time"),
    ("posterior.json", "posterior over the candidate goals after each observation prefix, with entropies"),
    ("posterior.png", "figure: posterior probability of each candidate goal over time"),
    ("fit.json", "fitted values, standard errors, residuals per condition and the fit's status"),
    ("model.yaml", "the fitted model, readable by 'comanip plan --preset model.yaml'"),
    ("model.json", "the fitted transition model (Gaussian process), readable by --transition-model"),
    # simulate's files before handover's: 'simulate handover' writes handover_near_trial0.csv
    ("*_trial*.csv", "one simulated trial, one row per time step: handle, rest position, stiffness, person's and robot's force"),
    ("sync_policies.csv", "robot policies compared: per goal and policy, median, q25 and q75 of every measure"),
    ("sync_policies.md", "the policy comparison as a markdown table (median [q25, q75])"),
    ("sync_policies.png", "figure: goal-estimate error over time and the measures per policy"),
    ("sync_speed_profiles.png", "figure: the person's x–y and the robot's z speed over t / MT per goal and policy, mean ± std"),
    ("*_summary.json", "settings, per-trial metrics and their summaries for every goal"),
    ("handover_*.json", "handover schedule for one goal: transition time and position, stiffness over time"),
    ("handover_*.csv", "handover schedule for one goal, one row per time: rest position and stiffness"),
    ("*_frames.png", "rendered frame strip of the first trial"),
    ("goals.csv", "ROS replay: every goal estimate the node published, with its covariance and latency"),
    ("prediction.csv", "ROS replay: the last predicted hand path the node published"),
    ("schedule.csv", "ROS replay: the last handover schedule the node published"),
    ("commands.csv", "ROS replay: every impedance rest position and stiffness the node commanded"),
    ("status.csv", "ROS replay: every diagnostics message (stale flag, counts, last solve status)"),
    ("report.json", "every number of the validation run"),
    ("report.md", "the run's report, readable: its tables (validate) or what to look at (demo)"),
    ("demo.json", "the demo's numbers: the plan, the online prediction's error along the recorded reach, the sync trial's measures"),
    ("online_prediction.png", "figure: the recorded hand path with the goal predicted at each update, and the prediction error"),
    ("franka_plans/*.csv", "one Panda reach's plan, one row per step"),
    ("franka_reaches.csv", "one row per Panda reach: goal, status, timing, joint-limit usage"),
    ("transition_data.csv", "transition distances over the (D/L, w) grid, one row per condition"),
    ("transition_data.json", "how transition_data.csv was generated: command, seed, model, wall time"),
    ("trends.json", "the published trends checked on the fitted transition model"),
    ("transition_model.png", "Fig. 2: the predicted transition distance over (D/L, w) with the data"),
    ("*.png", "figure"),
    ("*.csv", "table (CSV with a header row)"),
    ("*.json", "results (JSON)"),
)
"""(file-name pattern, what the file is), first match wins"""


def add_output_arguments(parser: argparse.ArgumentParser, default: str | None, what: str = "output folder",
                         default_text: str | None = None) -> None:
    """--out (default ``default``, described as ``default_text`` when given), --force and --verbose."""
    parser.add_argument("--out", default=default, help=f"{what} (default: {default_text or '%(default)s'})")
    parser.add_argument("--force", action="store_true", help="write into an output folder that holds another command's results")
    parser.add_argument("--verbose", action="store_true", help="print the full results (JSON, tables) instead of a short summary")


def output_dir(path: str | Path, command: str, force: bool = False, create: bool = True) -> Path:
    """The folder ``path``, created unless ``create`` is False (the caller creates it after further checks);
    ValueError when it is a file, or holds another command's results (its manifest names another command) and
    ``force`` is False."""
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {str(out)!r} is a file; expected a folder")
    owner = _owner(out)
    if owner not in (None, command) and not force:
        raise ValueError(f"--out {str(out)!r} holds the results of 'comanip {owner}'; give another --out, or --force "
                         "to write into it anyway")
    if create:
        out.mkdir(parents=True, exist_ok=True)
    return out


def write_manifest(out: Path, command: str, files, action: str | None = None) -> Path:
    """Write ``out/manifest.json``: the command, its arguments, the time, and a description of each of ``files``
    (paths in out). The files an earlier run of the same command (and ``action``, e.g. 'fit' of 'transition')
    listed and this run did not write are removed; another action's files stay listed."""
    out = Path(out)
    path = out / MANIFEST
    names = [Path(file).resolve().relative_to(out.resolve()).as_posix() for file in files]
    previous = _read(path) if _owner(out) == command else {}
    runs = dict(previous.get("runs", {})) if action else {}
    key = f"{command} {action}" if action else command
    earlier = runs.get(key, []) if action else list(previous.get("files", {}))
    _remove_stale(out, [name for name in earlier if name not in names and name != MANIFEST])
    kept = {name: text for name, text in previous.get("files", {}).items()
            if action and name not in earlier and (out / name).exists()}
    entries = kept | {name: _describe(name, command) for name in names}
    manifest = {"command": command, "arguments": shlex.join(sys.argv[1:]), "written": time.strftime("%Y-%m-%d %H:%M:%S"),
                "files": dict(sorted(entries.items()))}
    if action:
        runs[key] = sorted(names)
        manifest["runs"] = {name: files for name, files in sorted(runs.items()) if set(files) & set(entries)}
    path.write_text(json.dumps(manifest, indent=1))
    return path


def report(args: argparse.Namespace, lines: Sequence[str], full, out: Path, files: Sequence) -> None:
    """Print the outcome: with ``--verbose`` ``full`` (a dict or list as JSON, or text as it is), else the
    short summary ``lines`` and where the files are."""
    if getattr(args, "verbose", False):
        print(full if isinstance(full, str) else json.dumps(full, indent=1, default=_plain))
        return
    for line in lines:
        print(line)
    print(f"wrote {len(files)} file{'s' if len(files) != 1 else ''} to {out} (listed in {Path(out) / MANIFEST}; --verbose prints the full results)")


def write_table(path: Path, header: Sequence[str], rows) -> Path:
    """A CSV with a header row: each row's numbers to 9 significant digits (NaN as 'nan'), its text as it is."""
    with open(path, "w", encoding="utf-8") as file:
        file.write(",".join(header) + "\n")
        for row in rows:
            file.write(",".join(value if isinstance(value, str) else f"{float(value):.9g}" for value in row) + "\n")
    return Path(path)


def point_text(x) -> str:
    """A point (d,) as '(0.3, 0.1)' for a summary line."""
    return "(" + ", ".join(f"{float(v):.4g}" for v in x) + ")"


def warn(command: str, warnings: Sequence[str]) -> None:
    """One line on stderr per warning: 'comanip <command>: warning: ...'."""
    for text in warnings:
        print(f"comanip {command}: warning: {text}", file=sys.stderr)


def _plain(value):
    """JSON for numpy scalars and arrays."""
    return value.tolist() if hasattr(value, "tolist") else str(value)


def _remove_stale(out: Path, names: list[str]) -> None:
    """Remove the files ``names`` (relative to out) of an earlier run, and any folder in out they leave empty."""
    root = out.resolve()
    for name in names:
        file = (out / name).resolve()
        if root not in file.parents or not file.is_file():
            continue
        file.unlink()
        folder = file.parent
        while folder != root and folder.is_dir() and not any(folder.iterdir()):
            folder.rmdir()
            folder = folder.parent


def _describe(name: str, command: str) -> str:
    """What the file ``name`` (relative to its output folder) is, from :data:`FILE_KINDS`."""
    for pattern, text in FILE_KINDS:
        if fnmatch(name, pattern):
            return text
    return f"see 'comanip {command} --help'"


def _owner(out: Path) -> str | None:
    """The command named by out's manifest, or None (no folder, no manifest, or an unreadable one)."""
    return _read(out / MANIFEST).get("command")


def _read(path: Path) -> dict:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}
