"""Motion-capture recordings: the tracker CSV and the TAT-HUM layout (on files the tests write, and on the
arm reaches in ../shared where present), lost samples as gaps, and the stream a live tracker delivers."""

from pathlib import Path

import numpy as np
import pytest

from comanip.recordings import load_tathum, read_tracker_csv

ARMS = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"


def minimum_jerk(t, t0, T, offset):
    s = np.clip((t - t0) / T, 0.0, 1.0)[:, None]
    return offset * (10 * s**3 - 15 * s**4 + 6 * s**5)


def write_tathum(folder: Path, trials: dict, log_rows: list[str]):
    """A TAT-HUM folder for participant par7: {trial number: rows (K, 5) or None for an empty file}."""
    (folder / "trajectory_data" / "par7").mkdir(parents=True)
    (folder / "trial_data").mkdir()
    for number, rows in trials.items():
        path = folder / "trajectory_data" / "par7" / f"par7_trial_{number}.csv"
        path.write_text("" if rows is None else "\n".join(",".join(f"{v:.6f}" for v in row) for row in rows) + "\n")
    (folder / "trial_data" / "par7_tathum.csv").write_text(
        "trials.thisN,target,soa,keep_trial,trials.thisRepN,other\n,,,,,calibration\n" + "\n".join(log_rows) + "\n")


def tathum_rows(offset_mm, lost=()):
    t = np.arange(1, 376) * 0.004
    position = np.array([100.0, 40.0, 270.0]) + minimum_jerk(t, 0.5, 0.4, np.asarray(offset_mm, dtype=float))
    position[list(lost)] = 0.0                                   # the tracker's lost marker
    return np.column_stack([t, 1000 + np.arange(len(t)), position])


def test_a_tathum_folder_reads_in_metres_with_lost_samples_as_gaps_and_the_log_applied(tmp_path):
    write_tathum(tmp_path, {1: tathum_rows([200, 0, 0], lost=[150, 151, 152]), 2: tathum_rows([-150, 100, 50]),
                            3: None, 5: tathum_rows([0, 200, 0]), 6: tathum_rows([0, 0, 100])},
                 ["1,1,100,True,1,", "2,2,1100,True,2,", "3,1,100,True,1,", "5,2,100,False,1,", "6,1,100,True,0,"])
    trials = load_tathum(tmp_path)
    assert [t.name for t in trials] == ["par7/1", "par7/2"]             # 3 empty, 5 rejected, 6 practice
    assert trials[1].label == {"participant": "par7", "trial": 2, "target": 2, "soa_ms": 1100.0, "block": 2}
    first = trials[0]
    assert np.isnan(first.position[150:153]).all() and first.tracked.sum() == 372
    recording = first.recording()
    assert abs(recording.distance - 0.2) < 2e-3                          # mm read as m, the gap bridged
    assert abs(recording.movement_time - 0.4 * 0.88) < 0.03              # minimum jerk: 5 % to 5 % of the peak
    assert len(load_tathum(tmp_path, include_rejected=True, include_practice=True)) == 4


def test_a_tracker_stream_gives_backward_difference_velocities_and_nan_where_the_marker_was_lost(tmp_path):
    write_tathum(tmp_path, {1: tathum_rows([200, 0, 0], lost=[150, 151])}, ["1,1,100,True,1,"])
    [trial] = load_tathum(tmp_path)
    t, position, velocity = trial.stream(start=0.3, stop=0.8)
    assert np.allclose(np.diff(t), 0.008) and abs(t[0]) < 1e-9          # every second sample of 250 Hz
    k = int(np.argmin(np.abs(t - 0.2)))                                  # 0.5 s on the trial's clock
    raw = trial.t - trial.first_tracked
    i = int(np.argmin(np.abs(raw - (0.3 + t[k]))))
    j = int(np.argmin(np.abs(raw - (raw[i] - 0.024))))
    np.testing.assert_allclose(velocity[k], (trial.position[i] - trial.position[j]) / (raw[i] - raw[j]))
    lost = np.flatnonzero(np.isnan(position[:, 0]))
    assert lost.size == 1 and np.isnan(velocity[lost]).all()


def test_a_tracker_csv_reads_gaps_and_refuses_millimetres_and_time_going_back(tmp_path):
    path = tmp_path / "hand.csv"
    path.write_text("t,x,y,z\n0.00,0.10,0.20,0.30\n0.01,,,\n0.02,0.11,0.20,nan\n0.03,0.12,0.21,0.30\n")
    samples = read_tracker_csv(path)
    assert samples.position.shape == (4, 3) and samples.tracked.tolist() == [True, False, False, True]
    path.write_text("t,x,y,z\n0.00,100,200,300\n0.01,4000,200,300\n")
    with pytest.raises(ValueError, match="millimetres"):
        read_tracker_csv(path)
    path.write_text("t,x,y\n0.00,0.1,0.2\n0.02,0.1,0.2\n0.01,0.1,0.2\n")
    with pytest.raises(ValueError, match="sample 3 .* does not"):
        read_tracker_csv(path)
    path.write_text("time,x,y\n0.00,0.1,0.2\n")
    with pytest.raises(ValueError, match="needs the columns t, x, y"):
        read_tracker_csv(path)


@pytest.mark.skipif(not ARMS.is_dir(), reason="the recorded arm reaches (../shared/data/arm_reaches) are not beside this clone")
def test_the_recorded_arm_reaches_load_as_arm_reaches():
    trials = load_tathum(ARMS)
    assert len(trials) > 150 and {t.label["target"] for t in trials} == {1, 2}
    recordings = [t.recording() for t in trials]
    distance = np.median([r.distance for r in recordings])
    movement_time = np.median([r.movement_time for r in recordings])
    assert 0.15 < distance < 0.3 and 0.25 < movement_time < 0.6         # a reach of an arm, in m and s
    assert all(np.linalg.norm(r.velocity, axis=1).max() < 3.0 for r in recordings)
