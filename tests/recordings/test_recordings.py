"""Recordings: preprocessing (resampling, velocity, onset and end) on synthetic movements with known answers,
the loaders and their splits."""

import numpy as np
import pytest

from comanip.recordings import load_csv_recordings, load_cursory, recording_from_samples
from comanip.recordings.cursory_data import HELD_OUT_EVERY, split_indices
from comanip.recordings.preprocessing import movement_bounds, resample


def minimum_jerk(t, t0, T, D):
    """Position and speed (m, m/s) of a minimum-jerk movement of distance D m over [t0, t0 + T] s."""
    s = np.clip((t - t0) / T, 0.0, 1.0)
    return D * (10 * s**3 - 15 * s**4 + 6 * s**5), D * 30 * s**2 * (1 - s) ** 2 / T


def threshold_times(t0, T, fraction=0.05):
    """When a minimum-jerk speed rises above and falls below ``fraction`` of its peak (s)."""
    s = np.linspace(0, 1, 200001)
    above = s[30 * s**2 * (1 - s) ** 2 > fraction * 30 / 16]
    return t0 + T * above[0], t0 + T * above[-1]


def test_onset_end_and_velocity_of_a_synthetic_minimum_jerk_movement():
    rng = np.random.default_rng(0)
    t0, T, D = 0.2, 0.5, 0.3
    t = np.sort(np.r_[0.0, rng.uniform(0, 1.0, 150), 1.0])        # irregular samples, rest before and after
    direction = np.array([0.6, 0.8])
    position, _ = minimum_jerk(t, t0, T, D)
    recording = recording_from_samples("synthetic", t, position[:, None] * direction, step=0.005)
    onset, _ = threshold_times(t0, T, 0.025)         # the onset: where the speed last was below half the threshold
    _, end = threshold_times(t0, T)                  # the end: after the speed last was above 5 % of its peak
    assert abs(recording.onset - onset) <= 0.011 and abs(recording.end_time - end) <= 0.011
    assert abs(recording.distance - D) < 0.01 * D
    inside = (recording.t > t0 + 0.1 * T) & (recording.t < t0 + 0.9 * T)
    _, speed = minimum_jerk(recording.t[inside], t0, T, D)
    peak = 1.875 * D / T
    assert np.abs(recording.velocity[inside] @ direction - speed).max() < 0.03 * peak
    assert recording.seen_until(0.5) == int(np.searchsorted(recording.t, recording.onset + 0.5 * recording.movement_time, "right"))


def test_a_pause_between_samples_holds_the_hand_and_a_corrective_sub_movement_stays_inside():
    # a primary movement to 0.25 m, a 0.4 s pause without samples (an event-driven mouse), then a correction to 0.3 m
    t1 = np.arange(0.0, 0.5, 0.01)
    p1, _ = minimum_jerk(t1, 0.0, 0.5, 0.25)
    t2 = np.arange(0.9, 1.3, 0.01)
    p2, _ = minimum_jerk(t2, 0.9, 0.3, 0.05)
    t, p = np.r_[t1, t2], np.r_[p1, 0.25 + p2]
    grid, resampled = resample(t, np.c_[p, np.zeros_like(p)], step=0.01)
    during = (grid > 0.55) & (grid < 0.88)
    assert np.allclose(resampled[during, 0], p1[-1])                 # held, not drifting towards the next sample
    recording = recording_from_samples("two parts", t, np.c_[p, np.zeros_like(p)])
    assert recording.end_time > 1.0 and abs(recording.end[0] - 0.3) < 2e-3


def test_samples_at_one_time_are_averaged():
    grid, position = resample([0.0, 0.01, 0.01, 0.02], [[0.0], [1.0], [3.0], [2.0]], step=0.01)
    assert np.allclose(position[:, 0], [0.0, 2.0, 2.0])


@pytest.mark.parametrize("t, position, match", [
    ([0.0], [[0.0]], "N ≥ 2"),
    ([0.0, np.nan], [[0.0], [1.0]], "finite"),
    ([0.1, 0.0], [[0.0], [1.0]], "non-decreasing"),
])
def test_bad_samples_raise(t, position, match):
    with pytest.raises(ValueError, match=match):
        resample(t, position)


def test_a_recording_that_never_moves_has_no_onset():
    with pytest.raises(ValueError, match="never moves"):
        movement_bounds(np.arange(5.0), np.zeros((5, 2)))


def test_the_held_out_split_is_every_fifth_movement_and_disjoint_from_development():
    development, held_out = split_indices(2356, "development"), split_indices(2356, "held_out")
    assert np.all(held_out % HELD_OUT_EVERY == 0) and np.all(development % HELD_OUT_EVERY != 0)
    assert sorted(np.r_[development, held_out].tolist()) == list(range(2356))
    with pytest.raises(ValueError, match="split must be one of"):
        split_indices(10, "test")


def test_cursory_movements_load_at_the_scale_asked_for():
    pytest.importorskip("cursory")
    small = load_cursory("development", limit=5, scale=0.0005)
    large = load_cursory("development", limit=5, scale=0.001)
    assert [r.name for r in small] == ["cursory/1", "cursory/2", "cursory/3", "cursory/4", "cursory/6"]
    for a, b in zip(small, large):
        assert b.distance == pytest.approx(2 * a.distance, rel=1e-9)
        assert b.movement_time == pytest.approx(a.movement_time)
        assert 0.1 < a.movement_time < 3.0 and np.linalg.norm(a.end - a.target) < 0.2 * a.distance


def test_csv_recordings_are_preprocessed_with_their_targets(tmp_path):
    t = np.arange(0.0, 0.8, 0.01)
    x, _ = minimum_jerk(t, 0.1, 0.5, 0.2)
    rows = ["t,x,y,goal_x,goal_y,width"] + [f"{a:.3f},{b:.6f},0.0,0.2,0.0,0.02" for a, b in zip(t, x)]
    (tmp_path / "reach.csv").write_text("\n".join(rows) + "\n")
    [recording] = load_csv_recordings(tmp_path / "reach.csv")
    assert recording.name == "reach" and recording.width == 0.02
    assert np.allclose(recording.target, [0.2, 0.0]) and abs(recording.distance - 0.2) < 2e-3


def test_a_recording_refuses_nan_and_bad_shapes_and_warns_about_millimetres():
    from comanip.recordings import Recording
    t = np.linspace(0.0, 1.0, 11)
    position = np.c_[0.3 * t, 0 * t]
    Recording("ok", t, position, np.gradient(position, t, axis=0), 0.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        Recording("lost", t, np.where(t[:, None] == 0.5, np.nan, position), position, 0.0, 1.0)
    with pytest.raises(ValueError, match="shapes"):
        Recording("short", t, position[:5], position[:5], 0.0, 1.0)
    with pytest.raises(ValueError, match="increase"):
        Recording("back", t[::-1], position, position, 0.0, 1.0)
    with pytest.warns(UserWarning, match="millimetres"):
        Recording("mm", t, 1000 * position, 1000 * position, 0.0, 1.0)
