"""Output folders: own defaults, no silent overwrite of another command's results, a manifest in each."""

import json

import pytest

from comanip.cli.main import build_parser, main


def test_every_command_has_its_own_default_folder():
    parser = build_parser()
    defaults = {name: parser.parse_args(argv).out for name, argv in {
        "plan": ["plan"], "estimate": ["estimate"], "fit": ["fit", "--mt-table", __file__], "handover": ["handover"],
        "simulate": ["simulate", "sync"], "transition": ["transition", "fit"]}.items()}
    assert all(out.startswith(f"out/{name}") for name, out in defaults.items()), defaults


def test_validate_writes_to_a_folder_named_for_its_preset():
    """Was one out/validate for every preset: 'validate --preset human' replaced the planar report."""
    from pathlib import Path

    from comanip.cli.validate_command import default_folder

    assert build_parser().parse_args(["validate"]).out is None
    assert default_folder("planar") == Path("out/validate/planar")
    assert default_folder("human") == Path("out/validate/human")
    assert default_folder("models/mine.yaml") == Path("out/validate/mine")


def test_plan_writes_a_manifest_and_another_command_needs_force(tmp_path, capsys):
    out = tmp_path / "shared"
    assert main(["plan", "--out", str(out)]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["command"] == "plan" and set(manifest["files"]) == {"plan.json", "plan.csv"}
    assert "torques" in manifest["files"]["plan.json"]
    assert main(["plan", "--goal", "0.2,0.1", "--out", str(out)]) == 0          # the same command rewrites its own
    capsys.readouterr()
    argv = ["estimate", "--observed", "0.01,0,0.3,0", "--t-obs", "0.1", "--out", str(out)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds the results of 'comanip plan'" in err and "--force" in err
    assert not (out / "estimate.json").exists()
    assert main(argv + ["--force"]) == 0
    assert json.loads((out / "manifest.json").read_text())["command"] == "estimate"


def test_a_file_given_as_the_output_folder_is_one_line(tmp_path, capsys):
    (tmp_path / "taken").write_text("x")
    assert main(["plan", "--out", str(tmp_path / "taken")]) == 2
    assert "is a file; expected a folder" in capsys.readouterr().err


def test_manifest_describes_simulated_handover_trials_as_trials(tmp_path):
    """'simulate handover' writes handover_<goal>_trial<k>.csv and handover_summary.json: they are trials and a
    summary, not the schedules 'comanip handover' writes as handover_<k>.csv/json."""
    import json

    from comanip.cli.outputs import write_manifest

    names = ["handover_near_trial0.csv", "handover_summary.json", "handover_0.csv", "handover_0.json"]
    for name in names:
        (tmp_path / name).write_text("x")
    write_manifest(tmp_path, "simulate", [tmp_path / n for n in names])
    text = json.loads((tmp_path / "manifest.json").read_text())["files"]
    assert "simulated trial" in text["handover_near_trial0.csv"]
    assert "per-trial metrics" in text["handover_summary.json"]
    assert "schedule" in text["handover_0.csv"] and "schedule" in text["handover_0.json"]


def test_file_kinds_name_each_pattern_once():
    """FILE_KINDS is first-match-wins: a pattern listed twice has a description nothing can reach."""
    from comanip.cli.outputs import FILE_KINDS

    patterns = [pattern for pattern, _ in FILE_KINDS]
    assert len(patterns) == len(set(patterns)), sorted(p for p in set(patterns) if patterns.count(p) > 1)


def test_a_command_run_again_replaces_its_previous_outputs(tmp_path, capsys):
    """Was: the files of the first run stayed beside the second's. The manifest lists exactly this run's files."""
    out = tmp_path / "plan"
    assert main(["plan", "--out", str(out), "--png"]) == 0
    assert (out / "plan.png").exists()
    assert main(["plan", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "plan.csv", "plan.json"]
    assert set(json.loads((out / "manifest.json").read_text())["files"]) == {"plan.json", "plan.csv"}


def test_rewriting_removes_only_the_files_its_own_earlier_run_listed(tmp_path):
    from comanip.cli.outputs import write_manifest

    (tmp_path / "sub").mkdir()
    for name in ("a.csv", "sub/b.csv", "mine.txt"):
        (tmp_path / name).write_text("x")
    write_manifest(tmp_path, "simulate", [tmp_path / "a.csv", tmp_path / "sub/b.csv"])
    (tmp_path / "c.csv").write_text("x")
    write_manifest(tmp_path, "simulate", [tmp_path / "c.csv"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.csv", "manifest.json", "mine.txt"]   # sub/ left empty: gone


def test_transition_actions_share_a_folder_and_each_replaces_only_its_own_files(tmp_path):
    from comanip.cli.outputs import write_manifest

    for name in ("data.csv", "data.json", "model.json", "trends.json", "old.csv", "old.json"):
        (tmp_path / name).write_text("x")
    write_manifest(tmp_path, "transition", [tmp_path / "old.csv", tmp_path / "old.json"], action="generate")
    write_manifest(tmp_path, "transition", [tmp_path / "model.json", tmp_path / "trends.json"], action="fit")
    write_manifest(tmp_path, "transition", [tmp_path / "data.csv", tmp_path / "data.json"], action="generate")
    manifest = json.loads((tmp_path / "manifest.json").read_text())
    assert set(manifest["files"]) == {"data.csv", "data.json", "model.json", "trends.json"}
    assert not (tmp_path / "old.csv").exists() and (tmp_path / "model.json").exists()
    assert manifest["runs"] == {"transition fit": ["model.json", "trends.json"], "transition generate": ["data.csv", "data.json"]}


def test_stdout_is_a_short_summary_and_verbose_prints_the_json(tmp_path, capsys):
    assert main(["plan", "--out", str(tmp_path / "a")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 2 and lines[0].startswith("plan (planar): solved") and str(tmp_path / "a") in lines[1]
    assert main(["plan", "--out", str(tmp_path / "b"), "--verbose"]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "solved"


def test_help_is_fast_because_the_cli_imports_lazily():
    """'comanip --help' imports no solver, plotting or simulation package (it took 2.4 s when it did)."""
    import subprocess
    import sys

    code = ("import sys; from comanip.cli.main import build_parser; build_parser(['--help']); "
            "print(' '.join(sorted(m for m in sys.modules if m.split('.')[0] in ('casadi', 'scipy', 'matplotlib', 'mujoco', "
            "'dask', 'sklearn', 'rclpy'))))")
    heavy = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert heavy == [], heavy


@pytest.mark.slow
def test_simulate_again_into_its_folder_keeps_only_this_runs_files_and_leaks_no_warning(tmp_path, capsys):
    """Were 67 files after 'simulate sync --policy all' then 'simulate sync', the manifest naming the last run's
    only, and numpy's 'All-NaN slice encountered' on the terminal (the comparison figure's error percentiles
    before the first estimate)."""
    import warnings

    out = tmp_path / "sim"
    argv = ["simulate", "sync", "--trials", "1", "--goal", "near", "--no-frames", "--out", str(out)]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert main([*argv, "--policy", "all"]) == 0
    assert len(capsys.readouterr().out.splitlines()) <= 4
    assert main(argv) == 0
    listed = set(json.loads((out / "manifest.json").read_text())["files"])
    assert {p.name for p in out.iterdir()} == listed | {"manifest.json"}
    assert "sync_policies.md" not in listed
