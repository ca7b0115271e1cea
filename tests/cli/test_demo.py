"""``comanip demo``: the main job on defaults writes its figures, numbers and report, and the numbers say the
online prediction found the recorded person's goal and the robot ended beside them."""

import json

import pytest

from comanip.cli.main import main

pytest.importorskip("mujoco", reason="the demo's robot needs the 'sim' extra")


@pytest.mark.slow
def test_demo_predicts_the_recorded_goal_and_reports_what_to_look_at(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("plan: solved") and any("report.md" in line for line in lines)
    for name in ("plan.png", "online_prediction.png", "sync.png", "demo.json", "report.md", "manifest.json"):
        assert (out / name).stat().st_size > 0, name
    numbers = json.loads((out / "demo.json").read_text())
    assert numbers["plan"]["success"]
    online = numbers["online_prediction"]
    assert online["updates"] > 10 and online["recording"].startswith("cursory/")
    assert online["error_m"]["1.0"] < 0.05            # at the end of the reach the prediction is within 5 cm
    assert numbers["sync"]["final_error_m"] < 0.05    # and the handle ends at the person's goal
    report = (out / "report.md").read_text()
    assert all(f"`{name}`" in report for name in ("plan.png", "online_prediction.png", "sync.png"))


def test_demo_refuses_a_negative_seed_in_one_line(tmp_path, capsys):
    assert main(["demo", "--seed", "-1", "--out", str(tmp_path / "demo")]) == 2
    assert capsys.readouterr().err.strip().count("\n") == 0
