"""Vicon Nexus trajectories exports: on exports the tests write (units, markers, gaps, a broken header, a trial
holding more than its reach) and on the UE_ADL people in ../shared where present."""

from pathlib import Path

import numpy as np
import pytest

from comanip.estimation.hand_rest import resting_position
from comanip.recordings import load_nexus_trajectories, read_nexus_trajectories
from comanip.recordings.hand_states import read_hand_states
from comanip.recordings.trial_files import load_recordings

UE_ADL = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "ue_adl"
needs_ue_adl = pytest.mark.skipif(not UE_ADL.is_dir(), reason="the UE_ADL arm reaches (../shared/data/arm_reaches/ue_adl) "
                                                               "are not beside this clone")
RATE = 100.0
START_MM = np.array([250.0, -300.0, 100.0])


def minimum_jerk(t, t0, T, offset):
    s = np.clip((t - t0) / T, 0.0, 1.0)[:, None]
    return np.asarray(offset, dtype=float) * (10 * s**3 - 15 * s**4 + 6 * s**5)


def reach_mm(frames=300, offset=(300.0, 0.0, 0.0), onset=0.8, duration=0.9):
    """Fingertip positions (frames, 3) mm of a minimum-jerk reach from rest to rest at RATE."""
    t = np.arange(frames) / RATE
    return START_MM + minimum_jerk(t, onset, duration, offset)


def write_export(path: Path, markers: dict, *, units="mm", rate=RATE, first_line="Trajectories", subject="ADL099",
                 first_frame=1) -> Path:
    """A Nexus export of {marker: positions (K, 3) with NaN for a lost frame} as Nexus writes it."""
    frames = len(next(iter(markers.values())))
    names = ",".join(f"{subject}:{m},," if subject else f"{m},," for m in markers)
    lines = [first_line, f"{rate:g}", ",," + names, "Frame,Sub Frame" + ",X,Y,Z" * len(markers),
             ",," + ",".join([units] * 3 * len(markers))]
    for k in range(frames):
        cells = [str(first_frame + k), "0"]
        for values in markers.values():
            cells += ["" if np.isnan(v) else f"{v:.6f}" for v in values[k]]
        lines.append(",".join(cells))
    path.write_text("\ufeff" + "\n".join(lines) + "\n")
    return path


def test_an_export_reads_the_chosen_marker_in_metres_at_its_rate(tmp_path):
    hand = reach_mm()
    elbow = START_MM + 0.3 * (hand - START_MM) - [0.0, 0.0, 250.0]
    path = write_export(tmp_path / "ADL099FR2.csv", {"RSHO1": np.zeros_like(hand) + 100.0, "RFTP": hand, "RLEP": elbow},
                        first_frame=14)
    samples = read_nexus_trajectories(path)                        # the default: the fingertip of the arm in the name
    assert samples.label["marker"] == "ADL099:RFTP" and samples.label["rate_hz"] == RATE
    assert {k: samples.label[k] for k in ("participant", "task", "arm", "trial", "target")} == \
        {"participant": "ADL099", "task": "F", "arm": "R", "trial": 2, "target": "FR"}
    assert samples.t[0] == 0.0 and np.allclose(np.diff(samples.t), 1 / RATE)
    assert np.allclose(samples.position[0], START_MM / 1000)
    recording = samples.recording()
    assert abs(recording.distance - 0.3) < 2e-3
    assert abs(recording.onset - 0.8) < 0.06 and abs(recording.movement_time - 0.9 * 0.88) < 0.05
    elbow_samples = read_nexus_trajectories(path, "ADL099:RLEP")   # with the subject, and another marker
    assert abs(elbow_samples.recording().distance - 0.09) < 2e-3


def test_metres_and_millimetres_give_the_same_positions(tmp_path):
    hand = reach_mm()
    in_mm = read_nexus_trajectories(write_export(tmp_path / "a.csv", {"FTP": hand}), "FTP")
    in_m = read_nexus_trajectories(write_export(tmp_path / "b.csv", {"FTP": hand / 1000}, units="m"), "FTP")
    assert np.allclose(in_mm.position, in_m.position)
    with pytest.warns(UserWarning, match="look like millimetres"):   # millimetres the file calls metres
        read_nexus_trajectories(write_export(tmp_path / "c.csv", {"FTP": hand * 10}, units="m"), "FTP")
    with pytest.raises(ValueError, match=r"units \['in'\].*allowed: mm, cm, m"):
        read_nexus_trajectories(write_export(tmp_path / "d.csv", {"FTP": hand}, units="in"), "FTP")


def test_a_missing_marker_is_one_line_listing_the_markers(tmp_path):
    path = write_export(tmp_path / "ADL099FL1.csv", {"RFTP": reach_mm(), "RTHUM": reach_mm()})
    with pytest.raises(ValueError, match=r"no marker 'LFTP'; its markers: ADL099:RFTP, ADL099:RTHUM$") as error:
        read_nexus_trajectories(path)                               # the left fingertip, from the file's name
    assert "\n" not in str(error.value)
    nameless = write_export(tmp_path / "reach.csv", {"RFTP": reach_mm()})
    with pytest.raises(ValueError, match=r"names the arm of the file.*ADL099:RFTP"):
        read_nexus_trajectories(nameless)


def test_short_gaps_are_bridged_and_long_ones_refused_with_their_frames(tmp_path):
    hand = reach_mm()
    short, long = hand.copy(), hand.copy()
    short[120:124] = np.nan                                         # 4 frames, mid-reach
    long[120:130] = np.nan                                          # 10 frames
    bridged = read_nexus_trajectories(write_export(tmp_path / "s.csv", {"FTP": short}), "FTP")
    assert np.isnan(bridged.position[120:124]).all()                # a gap, never a position
    recording = bridged.recording()
    assert np.allclose(recording.position_at(1.215), hand[121:123].mean(axis=0) / 1000, atol=2e-3)
    path = write_export(tmp_path / "l.csv", {"FTP": long}, first_frame=1)
    with pytest.raises(ValueError, match=r"lost for 0\.1 s \(frames 121–130\); gaps of up to max_gap = 0\.05 s"):
        read_nexus_trajectories(path, "FTP")
    assert read_nexus_trajectories(path, "FTP", max_gap=0.1).tracked.sum() == len(hand) - 10
    edges = hand.copy()
    edges[:30] = np.nan                                             # lost before the first tracked frame: no gap
    assert read_nexus_trajectories(write_export(tmp_path / "e.csv", {"FTP": edges}), "FTP").first_tracked == 0.3


@pytest.mark.parametrize("change, message", [
    (lambda lines: ["Devices"] + lines[1:], r"line 1 must be 'Trajectories'"),
    (lambda lines: lines[:1] + ["fast"] + lines[2:], r"line 2 must be the frame rate in Hz .* it is 'fast'"),
    (lambda lines: lines[:3] + ["Frame,X,Y,Z"] + lines[4:], r"line 4 must start with 'Frame,Sub Frame"),
    (lambda lines: lines[:4], r"has 4 lines; a Nexus export has 5 header lines"),
    (lambda lines: lines[:5], r"has a header but no frames"),
    (lambda lines: lines[:7] + [lines[7].replace(",", ",x", 3)] + lines[8:], r"line 8, column 3: 'x.*' is not a number"),
])
def test_a_broken_export_is_one_line_naming_its_line(tmp_path, change, message):
    good = write_export(tmp_path / "good.csv", {"FTP": reach_mm()})
    broken = tmp_path / "broken.csv"
    broken.write_text("\n".join(change(good.read_text().lstrip("\ufeff").splitlines())) + "\n")
    with pytest.raises(ValueError, match=message) as error:
        read_nexus_trajectories(broken, "FTP")
    assert "\n" not in str(error.value)


def test_a_trial_is_cut_to_its_reach_when_the_hand_moves_again(tmp_path):
    t = np.arange(400) / RATE
    hand = reach_mm(400) + minimum_jerk(t, 3.2, 0.6, [-150.0, 0.0, 0.0])    # rests 1.5 s, then starts back
    hand = hand + minimum_jerk(t, 0.2, 0.1, [0.0, 4.0, 0.0])                  # a twitch before the reach
    samples = read_nexus_trajectories(write_export(tmp_path / "a.csv", {"FTP": hand}), "FTP")
    recording = samples.recording()
    assert abs(recording.distance - 0.3) < 3e-3                              # neither the twitch nor the way back
    assert 0.25 < samples.first_tracked < 0.5 and samples.t[-1] < 3.3        # from the rest after the twitch to the next
    assert abs(samples.first_tracked + recording.onset - 0.8) < 0.08
    whole = write_export(tmp_path / "b.csv", {"FTP": reach_mm(400) + minimum_jerk(t, 0.2, 0.1, [0.0, 4.0, 0.0])})
    assert read_nexus_trajectories(whole, "FTP").t[-1] == 3.99                 # a reach to rest keeps its last frame


def test_a_folder_of_people_is_read_by_the_fit_and_a_file_by_the_estimate(tmp_path):
    for person, scale in (("ADL098", 1.0), ("ADL099", 0.8)):
        (tmp_path / person).mkdir()
        for arm, sign in (("R", 1), ("L", -1)):
            for trial in (1, 2):
                hand = reach_mm(offset=(sign * 300.0 * scale, 10.0 * trial, 0.0))
                write_export(tmp_path / person / f"{person}F{arm}{trial}.csv", {f"{arm}FTP": hand, "STRN": hand * 0.0},
                             subject=person)
    trials = load_nexus_trajectories(tmp_path)
    assert [t.name for t in trials][:3] == ["ADL098/ADL098FL1", "ADL098/ADL098FL2", "ADL098/ADL098FR1"]
    assert len(trials) == 8 and len(load_nexus_trajectories(tmp_path, people=["ADL099"])) == 4
    fitted = load_recordings(tmp_path)                              # comanip fit --recordings FOLDER
    assert len(fitted) == 8
    by_name = {t.name: t for t in fitted}
    left = by_name["ADL099/ADL099FL1"]
    assert np.allclose(left.goal, (START_MM + [-240.0, 15.0, 0.0]) / 1000, atol=2e-3)   # the mean of the two ends
    assert abs(left.width - np.sqrt(np.mean([0.0, 0.005**2, 0.0]))) < 1e-3
    times, states = read_hand_states(tmp_path / "ADL098" / "ADL098FR1.csv", 3)       # comanip estimate --observations
    assert times[0] == 0.0 and states.shape == (len(times), 6)
    assert np.linalg.norm(states[-1, :3] - states[0, :3]) == pytest.approx(0.3, abs=3e-3)
    plain = tmp_path / "plain.csv"
    plain.write_text("t_s,q0,q1,q2,qdot0,qdot1,qdot2\n0,0,0,0,0,0,0\n0.1,0.01,0,0,0.2,0,0\n")
    with pytest.raises(ValueError, match="a marker and a longest gap choose the samples of a Nexus export"):
        read_hand_states(plain, 3, marker="RFTP")


@needs_ue_adl
def test_the_ue_adl_people_read_as_fingertip_reaches_from_rest_to_rest():
    trials = load_nexus_trajectories(UE_ADL)
    assert len(trials) == 200 and len({t.label["participant"] for t in trials}) == 10
    assert {t.label["rate_hz"] for t in trials} == {100.0}
    assert {t.label["marker"].split(":")[1] for t in trials} == {"RFTP", "LFTP"}
    assert all(t.label["marker"].endswith(":" + t.label["arm"] + "FTP") for t in trials)
    recordings = [t.recording() for t in trials]
    distances = np.array([r.distance for r in recordings])
    assert 0.25 < np.median(distances) < 0.35 and 0.08 < distances.min() and distances.max() < 0.55
    assert 0.17 < np.percentile(distances, 10) and np.percentile(distances, 90) < 0.45
    assert all(0.4 < r.movement_time < 2.0 for r in recordings)
    peaks = np.array([np.linalg.norm(r.velocity, axis=1).max() for r in recordings])
    assert 0.3 < peaks.min() and peaks.max() < 1.3
    at_rest = 0
    for samples, recording in zip(trials, recordings):
        t = samples.t - samples.first_tracked
        before, after = t <= recording.onset, t >= recording.end_time
        at_rest += (resting_position(t[before], samples.position[before]) is not None
                    and resting_position(t[after], samples.position[after]) is not None)
    assert at_rest >= 195                       # three of ADL007's trials begin as the hand moves
    streamed = [t.streamed_recording() for t, r in zip(trials, recordings) if r.onset >= 0.15]
    assert len(streamed) >= 195 and min(r.t[0] for r in streamed) >= 0.0       # times since the stream's start
