"""Output folders: own defaults, no silent overwrite of another command's results, a manifest in each."""

import json

from comanip.cli.main import build_parser, main


def test_every_command_has_its_own_default_folder():
    parser = build_parser()
    defaults = {name: parser.parse_args(argv).out for name, argv in {
        "plan": ["plan"], "estimate": ["estimate"], "fit": ["fit", "--mt-table", __file__], "handover": ["handover"],
        "simulate": ["simulate", "sync"], "validate": ["validate"], "transition": ["transition", "fit"]}.items()}
    assert all(out.startswith(f"out/{name}") for name, out in defaults.items()), defaults


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
