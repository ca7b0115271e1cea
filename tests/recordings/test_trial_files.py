"""Recorded reaches read as trials (comanip.recordings.trial_files): a trials table beside a folder of one-trial files,
and one-line errors for malformed files."""

import pytest

from comanip.recordings.trial_files import load_recordings


def test_trials_table_and_folder_of_one_trial_files(tmp_path):
    folder = tmp_path / "reaches"
    folder.mkdir()
    (folder / "a.csv").write_text("t,x,y\n0,0,0\n0.02,0.01,0\n0.04,0.03,0.001\n")
    (folder / "b.csv").write_text("t,x,y\n0,0,0\n0.01,0,0.02\n0.03,0,0.05\n0.05,0,0.06\n")
    (folder / "trials.csv").write_text("trial,goal_x,goal_y,width\na,0.3,0,0.02\nb,0,0.2,0.01\n")
    trials = load_recordings(folder, trials=folder / "trials.csv")
    assert [t.name for t in trials] == ["a", "b"]
    assert trials[1].goal.tolist() == [0.0, 0.2] and trials[1].width == 0.01 and len(trials[1].t) == 4


HEADER = "trial,t,x,y,goal_x,goal_y,width\n"


@pytest.mark.parametrize("content, message", [
    ("trial,t,x,goal_x,goal_y,width\n1,0,0,0.3,0,0.02\n", "lacks the columns ['y']"),
    (HEADER + "1,0,0,0,0.3,0,0.02\n1,0.04,0.01,0,0.3,0,0.02\n1,0.02,0.02,0,0.3,0,0.02\n", "t must increase"),
    ("", "is empty"),
    (HEADER, "no rows"),
    (HEADER + "1,0,0,0,0.3,0,0.02\n1,0.02,nan,0,0.3,0,0.02\n1,0.04,0.02,0,0.3,0,0.02\n", "must be finite"),
    (HEADER + "1,0,0,0,0.3,0,0.02\n1,0.02,abc,0,0.3,0,0.02\n1,0.04,0.02,0,0.3,0,0.02\n", "not a number"),
    (HEADER + "1,0,0,0,0.3,0,0.02\n1,0.02,0.01,0,0.3,0,0.04\n1,0.04,0.02,0,0.3,0,0.02\n", "changes within the trial"),
    ("trial,t,x,y\n1,0,0,0\n1,0.02,0.01,0\n1,0.04,0.02,0\n", "give a trials table"),
    (HEADER + "1,0,0,0,0.3,0,0.02\n1,0.02,0.01,0,0.3,0,0.02\n", "at least 3"),
])
def test_malformed_recordings_give_one_line_errors(tmp_path, content, message):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")) as error:
        load_recordings(path)
    assert "\n" not in str(error.value)


def test_an_empty_folder_and_a_missing_file(tmp_path):
    (tmp_path / "recordings").mkdir()
    with pytest.raises(ValueError, match="no .csv files"):
        load_recordings(tmp_path / "recordings")
    with pytest.raises(ValueError, match="does not exist"):
        load_recordings(tmp_path / "missing.csv")
