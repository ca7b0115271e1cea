"""The velocity derived from positions alone, one sample at a time: the rule recorded trials are streamed with, its
lag and noise on a known motion, and its start, gaps and bad stamps."""

import numpy as np
import pytest

from comanip.estimation.streaming.derived_velocity import DerivedVelocity
from comanip.recordings import load_tathum
from tests.recordings.test_motion_capture import tathum_rows, write_tathum


def test_the_velocity_is_the_streamed_trials_backward_difference(tmp_path):
    # at the tracker's own rate, with no marker lost, every velocity past the first window is the stream's
    write_tathum(tmp_path, {1: tathum_rows([200, -50, 30])}, ["1,1,100,True,1,"])
    [trial] = load_tathum(tmp_path)
    t, position, streamed = trial.stream(rate_hz=250.0)
    derived = DerivedVelocity()
    online = np.array([derived.add(stamp, p) for stamp, p in zip(t, position)])
    settled = np.flatnonzero(np.isfinite(streamed[:, 0]))
    assert settled.size > 300 and settled[0] <= 7
    np.testing.assert_allclose(online[settled], streamed[settled], rtol=1e-12, atol=1e-12)


def test_on_a_ramp_it_is_exact_and_on_a_noisy_rest_its_noise_is_the_windows():
    derived = DerivedVelocity(window=0.02)
    stamps = np.arange(0.0, 0.5, 0.004)
    ramp = np.array([derived.add(t, [0.3 * t, -0.1 * t]) for t in stamps])
    np.testing.assert_allclose(ramp[0], 0.0)                                    # a stream starts at rest
    np.testing.assert_allclose(ramp[1:], np.tile([0.3, -0.1], (len(stamps) - 1, 1)), atol=1e-12)
    rng = np.random.default_rng(3)
    resting = DerivedVelocity(window=0.02)
    noisy = np.array([resting.add(t, rng.normal(0.0, 1e-3, 2)) for t in stamps])[10:]
    # sqrt(2) sigma / window: 0.07 m/s for 1 mm of noise over 20 ms
    assert np.std(noisy) == pytest.approx(np.sqrt(2) * 1e-3 / 0.02, rel=0.2)


def test_a_gap_starts_the_stream_over_and_a_stamp_going_back_is_refused():
    derived = DerivedVelocity(window=0.02, restart_after=0.1)
    for t in np.arange(0.0, 0.1, 0.004):
        derived.add(t, [t])
    np.testing.assert_allclose(derived.add(0.5, [2.0]), [0.0])                  # after the gap: at rest again
    np.testing.assert_allclose(derived.add(0.504, [2.004]), [1.0])
    with pytest.raises(ValueError, match="stamps must increase"):
        derived.add(0.504, [2.0])
    with pytest.raises(ValueError, match="window"):
        DerivedVelocity(window=0.0)
