"""People chosen by name (``comanip simulate sync --person``): the model's, recorded, arm, paced, or a folder."""

import json
import shutil

import pytest

from comanip.cli.main import main
from comanip.simulation.people import SHIPPED_ARM_REACHES, choose_person
from comanip.simulation.person import PersonParameters


@pytest.mark.parametrize("name, hand_path, pace", [("model", "model", 1.0), ("model-x0.7", "model", 0.7),
                                                   ("arm", "recorded-arm", 1.0), ("arm-x2.5", "recorded-arm", 2.5),
                                                   ("arm-x.5", "recorded-arm", 0.5)])
def test_a_name_chooses_where_the_hand_path_comes_from_and_its_pace(name, hand_path, pace):
    person = choose_person(name)
    assert person.parameters == PersonParameters(hand_path=hand_path, pace=pace)
    assert person.arm_reaches == (SHIPPED_ARM_REACHES if hand_path == "recorded-arm" else None)


def test_the_shipped_arm_reaches_are_ten_recorded_reaches_that_play_as_reaches():
    from comanip.recordings import load_tathum
    from comanip.simulation.recorded_person import usable_for_reach

    trials = load_tathum(SHIPPED_ARM_REACHES)
    assert len(trials) == 10 and all(trial.label["trial"] % 4 != 0 for trial in trials)     # development split only
    assert all(usable_for_reach(trial.recording()) for trial in trials)
    assert (SHIPPED_ARM_REACHES.parent / "LICENSE").read_text().startswith("MIT License")


def test_a_folder_of_arm_reaches_is_a_person_even_when_its_name_ends_like_a_pace(tmp_path):
    folder = tmp_path / "lab-x3"
    shutil.copytree(SHIPPED_ARM_REACHES, folder)
    assert choose_person(str(folder)).parameters == PersonParameters(hand_path="recorded-arm")
    assert choose_person(str(folder)).arm_reaches == folder
    paced = choose_person(f"{folder}-x2")
    assert paced.parameters.pace == 2.0 and paced.arm_reaches == folder


@pytest.mark.parametrize("name, fragment", [("mouse", "neither a name nor a folder"), ("arm-x0", "must be a number > 0"),
                                            ("arm-xfast", "neither a name nor a folder"), ("", "the person must be")])
def test_bad_names_say_what_is_allowed(name, fragment):
    with pytest.raises(ValueError, match=fragment) as error:
        choose_person(name)
    assert "model, recorded, arm or a folder" in str(error.value) and "\n" not in str(error.value)


def test_a_folder_of_no_arm_reaches_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"neither in the TAT-HUM layout \(trajectory_data/ and trial_data/ inside\) nor"):
        choose_person(str(tmp_path))


class _Chosen(Exception):
    """Raised by the stand-in scenario runner with what the command line gave it."""


def test_the_command_lines_person_reaches_the_scenario(tmp_path, monkeypatch):
    import comanip.simulation.scenario_runs as scenario_runs

    def run_scenario(name, settings_by_goal, policies, arm_reaches=None):
        raise _Chosen(name, settings_by_goal, arm_reaches)

    monkeypatch.setattr(scenario_runs, "run_scenario", run_scenario)
    with pytest.raises(_Chosen) as chosen:
        main(["simulate", "sync", "--person", "arm-x2.5", "--goal", "near", "--carry-calibration", "--out", str(tmp_path / "out")])
    name, settings_by_goal, arm_reaches = chosen.value.args
    assert name == "sync" and arm_reaches == SHIPPED_ARM_REACHES
    assert settings_by_goal["near"].person == PersonParameters(hand_path="recorded-arm", pace=2.5)
    assert settings_by_goal["near"].carry_calibration


@pytest.mark.parametrize("argv, fragment", [(["sync", "--person", "walker"], "'walker' is neither a name nor a folder"),
                                            (["handover", "--person", "arm"], "--person applies to the sync scenario only"),
                                            (["handover", "--carry-calibration"], "--carry-calibration applies to the sync scenario only")])
def test_a_bad_person_on_the_command_line_is_one_line_before_any_work(tmp_path, capsys, argv, fragment):
    out = tmp_path / "out"
    assert main(["simulate", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err
    assert not out.exists()


@pytest.mark.slow
def test_simulate_sync_plays_a_shipped_arm_reach_slowed(tmp_path):
    pytest.importorskip("mujoco", reason="the scenario needs the 'sim' extra")
    out = tmp_path / "out"
    assert main(["simulate", "sync", "--person", "arm-x2.5", "--trials", "1", "--goal", "near", "--policy", "continuous",
                 "--no-frames", "--out", str(out)]) == 0
    summary = json.loads((out / "sync_summary.json").read_text())
    assert summary["settings"]["person"]["hand_path"] == "recorded-arm" and summary["settings"]["person"]["pace"] == 2.5
    trial, = summary["goals"]["near"]["trials"]
    assert trial["replans"] == 0                      # a recorded person does not re-plan
    assert trial["final_error_m"] < 0.01
