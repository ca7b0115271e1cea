"""``comanip demo``: the main job on defaults writes its figures, numbers and report; the numbers say the online
prediction found the recorded person's goal and the robot ended beside a person guiding the handle with forces
people apply, and the report's numbers are those of the series it writes."""

import csv
import json
import re

import numpy as np
import pytest

from comanip.cli.main import main

pytest.importorskip("mujoco", reason="the demo's robot needs the 'sim' extra")

OBJECT_WEIGHT_N = 1.5 * 9.81
"""The sync scenario's 1.5 kg object, which the robot leaves to the person."""


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "demo"
    assert main(["demo", "--out", str(out)]) == 0
    return out, json.loads((out / "demo.json").read_text()), (out / "report.md").read_text()


def _columns(path) -> dict[str, np.ndarray]:
    with open(path, newline="") as stream:
        rows = list(csv.DictReader(stream))
    return {name: np.array([float(row[name]) if row[name] not in ("", "nan") else np.nan for row in rows]) for name in rows[0]}


@pytest.mark.slow
def test_demo_predicts_the_recorded_goal_and_reports_what_to_look_at(demo_run):
    out, numbers, report = demo_run
    for name in ("plan.png", "online_prediction.png", "co_manipulation.png", "co_manipulation.csv", "forecasts.csv",
                 "sync_near_trial0.csv", "demo.json", "report.md", "manifest.json"):
        assert (out / name).stat().st_size > 0, name
    assert numbers["plan"]["success"]
    online = numbers["online_prediction"]
    assert online["updates"] > 10 and online["recording"].startswith("cursory/")
    assert online["error_m"]["1.0"] < 0.05            # at the end of the reach the prediction is within 5 cm
    assert numbers["sync"]["final_error_m"] < 0.05    # and the handle ends at the person's goal
    assert all(f"`{name}`" in report for name in ("plan.png", "online_prediction.png", "co_manipulation.png"))


@pytest.mark.slow
def test_the_person_beside_the_robot_is_an_arm_guiding_the_handle_with_forces_people_apply(demo_run):
    _, numbers, report = demo_run
    sync = numbers["sync"]
    assert sync["person"] == "arm-x2.5" and sync["recording"].startswith("par1/")
    assert sync["holding_force_N"] == pytest.approx(OBJECT_WEIGHT_N, abs=0.5)     # at rest the person holds the weight
    low, high = sync["guiding_force_N"]
    assert low <= sync["peak_force_change_N"] <= high                              # what the reach adds to it
    assert sync["peak_speed_m_per_s"] < 1.0                                       # a hand guiding a handle, not a fling
    assert "2.5 times slower" in report and "Sawers et al. 2017" in report


@pytest.mark.slow
def test_the_reports_forces_and_goal_errors_are_those_of_the_series_it_writes(demo_run):
    out, numbers, report = demo_run
    sync = numbers["sync"]
    series = _columns(out / "co_manipulation.csv")
    leading = series["t_s"] >= sync["observation_time_s"] - 1e-9
    force, change = series["force_N"][leading], series["force_change_N"][leading]
    assert force.max() == pytest.approx(sync["peak_force_N"], rel=1e-6)
    assert np.sqrt(np.mean(force**2)) == pytest.approx(sync["rms_force_N"], rel=1e-6)
    assert change.max() == pytest.approx(sync["peak_force_change_N"], rel=1e-6)
    assert np.sqrt(np.mean(change**2)) == pytest.approx(sync["rms_force_change_N"], rel=1e-6)
    assert series["force_N"][0] == pytest.approx(sync["holding_force_N"], rel=1e-6)
    assert series["goal_estimate_error_m"][-1] == pytest.approx(sync["goal_error_final_m"], abs=1e-6)
    for key in ("peak_force_N", "rms_force_N", "peak_force_change_N", "rms_force_change_N", "holding_force_N"):
        assert f"{sync[key]:.1f} N" in report, key
    assert f"is {1e3 * sync['goal_error_final_m']:.1f} mm" in report


@pytest.mark.slow
def test_the_forecasts_are_the_robots_and_their_errors_those_reported(demo_run):
    out, numbers, report = demo_run
    sync = numbers["sync"]
    series, rows = _columns(out / "co_manipulation.csv"), _columns(out / "forecasts.csv")
    assert len(sync["forecasts"]) == 3
    for forecast in sync["forecasts"]:
        mine = np.isclose(rows["made_at_s"], forecast["made_at_s"])
        error = rows["error_m"][mine]
        assert np.sqrt(np.mean(error**2)) == pytest.approx(forecast["rms_path_error_m"], rel=1e-6)
        # the estimator read back gives the goal the robot had at that time
        k = int(np.searchsorted(series["t_s"], forecast["made_at_s"] + 1e-9))
        assert series["goal_estimate_error_m"][k] == pytest.approx(forecast["goal_error_m"], abs=1e-6)
        assert f"{100 * forecast['rms_path_error_m']:.1f} cm RMS" in report
        assert rows["t_s"][mine][0] == pytest.approx(forecast["made_at_s"], abs=1e-3)   # a forecast from then on
    assert re.search(r"the predicted path of the hand against the hand\*\*.*not\s+the goal at the end", report, re.S)


def test_demo_refuses_a_negative_seed_in_one_line(tmp_path, capsys):
    assert main(["demo", "--seed", "-1", "--out", str(tmp_path / "demo")]) == 2
    assert capsys.readouterr().err.strip().count("\n") == 0


def test_demo_without_the_shipped_arm_reaches_says_where_they_are_before_any_work(tmp_path, capsys, monkeypatch):
    pytest.importorskip("cursory", reason="the demo reads the recorded people of the 'data' extra first")
    import comanip.simulation.people as people

    monkeypatch.setattr(people, "SHIPPED_ARM_REACHES", tmp_path / "absent")
    assert main(["demo", "--out", str(tmp_path / "demo")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "examples/data/arm_reaches" in err, err
    assert not (tmp_path / "demo").exists()
