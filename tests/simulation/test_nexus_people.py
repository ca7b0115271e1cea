"""Arm people played from Vicon Nexus exports (UE_ADL's layout): a person's folder, chosen by path, read alone."""

from pathlib import Path

import numpy as np
import pytest

from comanip.cli.main import main
from comanip.recordings import load_nexus_trajectories
from comanip.recordings import nexus_trajectories
from comanip.simulation import PersonParameters, ScenarioSetup, SyncSettings, choose_person
from comanip.simulation.recorded_person import recorded_reach, surface_normal, usable_for_reach
from tests.recordings.test_nexus_trajectories import reach_mm, write_export

UE_ADL = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "ue_adl"
needs_ue_adl = pytest.mark.skipif(not UE_ADL.is_dir(), reason="the UE_ADL arm reaches (../shared/data/arm_reaches/ue_adl) "
                                                               "are not beside this clone")


def _people(root: Path) -> Path:
    """A folder of two people's exports: ADL003 (three forward and across reaches with either arm) and a held-out
    ADL011 (one reach)."""
    for person, trials in (("ADL003", ("FR1", "AL2", "FL3")), ("ADL011", ("FR1",))):
        (root / person).mkdir(parents=True)
        for k, trial in enumerate(trials):
            offset = (300.0 - 20 * k, 40.0 * k - 40.0, 60.0 + 10 * k)
            write_export(root / person / f"{person}{trial}.csv", {f"{trial[1]}FTP": reach_mm(offset=offset)}, subject=person)
    return root


def _opened(monkeypatch) -> list[str]:
    """The paths the Nexus reader opens from now on."""
    opened = []

    def spy(path, *args, **kwargs):
        opened.append(str(path))
        return open(path, *args, **kwargs)

    monkeypatch.setattr(nexus_trajectories, "open", spy, raising=False)
    return opened


def test_a_persons_folder_of_nexus_exports_is_an_arm_person_read_alone(tmp_path, monkeypatch):
    people = _people(tmp_path / "people")
    opened = _opened(monkeypatch)
    person = choose_person(f"{people / 'ADL003'}-x2.5")
    assert person.parameters == PersonParameters(hand_path="recorded-arm", pace=2.5)
    assert person.arm_reaches == people / "ADL003"
    recordings = ScenarioSetup(SyncSettings(), arm_reaches=person.arm_reaches).arm_recordings
    assert [r.name for r in recordings] == ["ADL003/ADL003AL2", "ADL003/ADL003FL3", "ADL003/ADL003FR1"]
    assert opened and not any("ADL011" in path for path in opened)         # the held-out person is never read


@pytest.mark.parametrize("folder", ["synthetic", pytest.param("ue_adl", marks=needs_ue_adl)])
def test_a_nexus_persons_intended_path_is_their_fingertip_path_on_the_persons_axes(tmp_path, folder):
    person_folder = _people(tmp_path / "people") / "ADL003" if folder == "synthetic" else UE_ADL / "ADL003"
    read = [trial.recording() for trial in load_nexus_trajectories(person_folder)]     # the reader's own output
    usable = [recording for recording in read if usable_for_reach(recording)]
    settings = SyncSettings(goal="near")
    setup = ScenarioSetup(settings, arm_reaches=person_folder)
    start = setup.settled_start(np.zeros(3))
    for seed in range(3):
        parameters = PersonParameters(hand_path="recorded-arm", pace=2.5, led_axes=(0, 1))
        person = setup.person(start, settings.goal, seed, parameters=parameters)
        mine = next(r for r in usable if r.name == person.recording.name)
        np.testing.assert_array_equal(person.recording.position, mine.position)
        t, position = recorded_reach(mine, start.position, settings.goal, surface_normal(usable))
        intended = np.array([person.intended_motion(2.5 * time).displacement for time in t])
        np.testing.assert_allclose(intended[:, :2], (position - position[0])[:, :2], atol=1e-9)
        np.testing.assert_array_equal(intended[:, 2], 0.0)                # the height is the robot's


@pytest.mark.parametrize("argv, fragment", [
    (["--person", "{empty}"], "is neither in the TAT-HUM layout (trajectory_data/ and trial_data/ inside) nor holds "
                              "Vicon Nexus trajectories exports"),
    (["--person", "{empty}/ADL099-x2.5"], "neither a name nor a folder")])
def test_a_folder_without_arm_reaches_is_one_line_before_any_work(tmp_path, capsys, argv, fragment):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.csv").write_text("Frame,X\n1,2\n")
    out = tmp_path / "out"
    argv = [arg.format(empty=tmp_path / "empty") for arg in argv]
    assert main(["simulate", "sync", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err and "Vicon Nexus" in err, err
    assert not out.exists()
