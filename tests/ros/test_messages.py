"""The node's messages: a status value reads back as the number it was."""

import math

import pytest

pytest.importorskip("rclpy", reason="the ros extra is not installed")

from comanip.ros.messages import status_text  # noqa: E402


@pytest.mark.parametrize("value", [1795911093.131456789, 0.1, 1e-12, -2.5e8, 3.0])
def test_a_float_status_value_reads_back_exactly(value):
    assert float(status_text(value)) == value


def test_nan_and_booleans_read_as_words():
    assert status_text(math.nan) == "nan" and status_text(True) == "true" and status_text(False) == "false"
