"""benchmarks/forecast_peers.py: its learned forecaster reads only the past, is the same for a reach turned, moved and
scaled, and a person left out is never seen by the fit that scores them."""

import numpy as np
import pytest

from comanip.recordings import recording_from_samples
from tests.project.benchmark_scripts import load_benchmark


@pytest.fixture(scope="module")
def peers():
    """benchmarks/forecast_peers.py as a module."""
    return load_benchmark("forecast_peers")


def reach(name, offset, duration=0.8, start=(0.1, -0.2, 0.3), bend=0.0):
    """A minimum-jerk reach (m) from rest to rest at 100 Hz, bowed sideways by ``bend`` m mid-way."""
    t = np.arange(150) / 100.0
    s = np.clip((t - 0.3) / duration, 0.0, 1.0)[:, None]
    offset = np.asarray(offset, dtype=float)
    side = np.cross(offset, [0.0, 0.0, 1.0])
    side = side / np.linalg.norm(side)
    path = np.asarray(start) + offset * (10 * s**3 - 15 * s**4 + 6 * s**5) + bend * side * np.sin(np.pi * s) ** 2
    return recording_from_samples(name, t, path)


def turned(recording, rotation, shift, scale):
    """The recording turned by ``rotation`` (3, 3), scaled by ``scale`` and moved by ``shift`` (3,) m."""
    from comanip.recordings import Recording

    return Recording(recording.name + "'", recording.t, scale * recording.position @ rotation.T + shift,
                     scale * recording.velocity @ rotation.T, recording.onset, recording.end_time)


def rotation_about(axis, angle):
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def people_of_reaches():
    return {person: [reach(f"{person}/{k}", [scale * (0.2 + 0.02 * k), 0.05 * k, 0.0], duration=0.7 + 0.05 * k,
                           bend=0.01 * k) for k in range(3)]
            for person, scale in (("A", 1.0), ("B", 1.3), ("C", 0.8))}


def test_the_features_at_a_sample_read_only_the_samples_up_to_it(peers):
    original = reach("r", [0.3, 0.0, 0.0])
    k = 70
    position, velocity = original.position.copy(), original.velocity.copy()
    position[k + 1:] += 0.1
    velocity[k + 1:] *= 3
    before = peers.window_features(original.t, original.position, original.velocity, k)[0]
    assert np.array_equal(peers.window_features(original.t, position, velocity, k)[0], before)
    assert not np.allclose(peers.window_features(original.t, position, velocity, k + 2)[0], before)

def test_the_forecast_of_a_reach_turned_moved_and_scaled_is_the_forecast_turned_moved_and_scaled(peers):
    learned = peers.LearnedForecaster(max_iter=5).fit([r for rs in people_of_reaches().values() for r in rs])
    original = reach("r", [0.25, 0.05, 0.02], bend=0.02)
    rotation, shift = rotation_about([1.0, 2.0, 0.5], 1.1), np.array([0.5, -0.3, 0.9])
    for scale in (1.0, 2.0):
        other = turned(original, rotation, shift, scale)
        for k in (50, 65, 80):
            expected = scale * peers.kinematic_paths(original, k)["hand stays"] @ rotation.T + shift
            assert np.allclose(peers.kinematic_paths(other, k)["hand stays"], expected)
            assert np.allclose(peers.window_features(other.t, other.position, other.velocity, k)[0],
                               peers.window_features(original.t, original.position, original.velocity, k)[0], atol=1e-9)
            assert np.allclose(learned.predict(other, k), scale * learned.predict(original, k) @ rotation.T + shift,
                               atol=1e-6)


def test_a_person_left_out_is_never_seen_by_the_fit_that_scores_them(peers):
    people = people_of_reaches()
    probe = reach("probe", [0.27, -0.04, 0.01], bend=0.015)
    fit = lambda recordings: peers.LearnedForecaster(max_iter=5).fit(recordings)
    folds = dict(peers.leave_one_person_out(people, fit))
    assert list(folds) == ["A", "B", "C"]
    for person, learned in folds.items():
        assert set(learned.trained_on) == {r.name for other, rs in people.items() if other != person for r in rs}
    # person A's reaches changed: A's fold predicts the same, the folds that train on A do not
    altered = dict(people, A=[turned(r, np.eye(3), np.zeros(3), 1.8) for r in people["A"]])
    again = dict(peers.leave_one_person_out(altered, fit))
    assert np.array_equal(again["A"].predict(probe, 75), folds["A"].predict(probe, 75))
    assert not np.allclose(again["B"].predict(probe, 75), folds["B"].predict(probe, 75))


def test_the_tables_give_each_person_and_the_medians(peers):
    rows = [{"person": p, "movement": f"{p}/{k}", "forecaster": f, "from": fr, "lead_s": lead, "distance_m": 0.3,
             "error": e * (1 + k) + 0.01 * i}
            for p, e in (("A", 0.1), ("B", 0.3)) for k in range(3) for f in (*peers.KINEMATIC, peers.LEARNED)
            for fr in peers.FROM for i, lead in enumerate(peers.LEADS)]
    table = peers.medians(rows, [*peers.KINEMATIC, peers.LEARNED], ["A", "B"])
    assert table[0.25]["A"][peers.LEARNED] == pytest.approx([0.2, 0.21, 0.22])        # the median over A's reaches
    assert table[0.25]["median over people"][peers.LEARNED] == pytest.approx([0.4, 0.41, 0.42])
    assert table[0.5]["all reaches"][peers.LEARNED] == pytest.approx([0.3, 0.31, 0.32])
    text = peers.markdown(table, [*peers.KINEMATIC, peers.LEARNED], {"A": 3, "B": 3})
    assert "| A | 3 | 0.200 / 0.210 / 0.220 |" in text and "for 0 of 2 people" in text


def test_the_kept_people_models_are_read_back_only_for_the_reaches_and_features_they_were_fitted_on(peers, tmp_path, monkeypatch):
    from comanip.estimation.people.people_model import ARM_FEATURES, KINDS, PeopleModel

    people = people_of_reaches()
    fitted = peers.people_models(people, tmp_path)
    assert len(list(tmp_path.glob("*.npz"))) == len(people)
    probe = people["A"][1]
    original_fit, refitted = PeopleModel.fit, []
    monkeypatch.setattr(PeopleModel, "fit", lambda recordings, kind: refitted.append({r.name for r in recordings})
                        or original_fit(recordings, kind=kind))
    again = peers.people_models(people, tmp_path)
    assert refitted == []                                              # every fit read back
    seen = (probe.t[:60], probe.position[:60], probe.velocity[:60], probe.position[0])
    for person in people:
        assert np.array_equal(again[person].predict(*seen).goal, fitted[person].predict(*seen).goal)
    fewer = {**people, "B": people["B"][:2]}                          # B has one reach less: A's and C's fits change
    peers.people_models(fewer, tmp_path)
    assert sorted(map(sorted, refitted)) == sorted(sorted({r.name for p, rs in fewer.items() if p != left for r in rs})
                                                   for left in ("A", "C"))
    refitted.clear()                                                   # other features: every fit changes
    monkeypatch.setitem(KINDS, "arm", ARM_FEATURES[:-1])
    peers.people_models(fewer, tmp_path)
    assert len(refitted) == len(fewer)
