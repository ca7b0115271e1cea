"""comanip.units: recordings in ms or mm (or degrees) are told apart from s and m by their spans and steps."""

import numpy as np
import pytest

from comanip.units import check_angles_rad, check_positions_m, check_times_s

REACH_T = np.arange(0.0, 0.62, 0.02)                       # a 0.6 s reach sampled at 50 Hz, s
REACH_X = np.column_stack([np.linspace(0.0, 0.3, REACH_T.size), np.zeros(REACH_T.size)])  # a 0.3 m reach, m


def test_a_reach_in_seconds_and_metres_passes():
    assert check_times_s(REACH_T, "t") is not None
    assert check_positions_m(REACH_X, "x").shape == REACH_X.shape
    assert check_angles_rad([[0.1, -2.9, 3.0]], "q").shape == (1, 3)


@pytest.mark.parametrize("t", [1000 * REACH_T,                           # 50 Hz in ms: steps of 20
                               1000 * np.arange(0.0, 0.01, 0.001),       # 10 ms at 1 kHz in ms: steps of 1
                               1000 * np.arange(0.0, 0.6, 1e-4)])        # 10 kHz in ms: a span of 600
def test_times_in_milliseconds_are_named(t):
    with pytest.raises(ValueError, match="file 'r.csv', column 't': .*look like milliseconds") as error:
        check_times_s(t, "file 'r.csv', column 't'")
    assert "\n" not in str(error.value) and "check_units=False" in str(error.value)


def test_positions_in_millimetres_and_angles_in_degrees_are_named():
    with pytest.raises(ValueError, match="columns x, y: positions span 300 .*look like millimetres"):
        check_positions_m(1000 * REACH_X, "columns x, y")
    with pytest.raises(ValueError, match="look like degrees"):
        check_angles_rad([[0.0, -45.0, 90.0]], "q0..q2")
