"""benchmarks/person_calibration.py on recorded people: a singular region holds only what lies in its span, and the
person-by-person table's targets say which people the coverage bands hold."""

import numpy as np
import pytest

from tests.project.benchmark_scripts import load_benchmark


@pytest.fixture(scope="module")
def calibration():
    """benchmarks/person_calibration.py as a module."""
    return load_benchmark("person_calibration")


def test_a_flat_region_holds_only_what_lies_in_it(calibration):
    flat = np.diag([0.01, 0.01, 0.0])
    assert calibration.holds(np.array([0.05, 0.0, 0.0]), flat)
    assert not calibration.holds(np.array([0.05, 0.0, 1e-3]), flat)
    assert not calibration.holds(np.array([0.5, 0.0, 0.0]), flat)
    assert not calibration.holds(np.array([1e-3, 0.0, 0.0]), np.zeros((3, 3)))
    assert calibration.holds(np.array([0.2, 0.0, 0.0]), np.eye(3) * 0.01)


def rows(person, covered_first, covered_later, forecast_later, reaches=15):
    """Rows of both modes for one person: the endpoint's region holding on the first reach, and on the later
    reaches ``covered_later`` and ``forecast_later`` of the endpoint's and the forecast's regions holding (tenths)."""
    out = []
    for mode in ("calibrated", "not calibrated"):
        count = 0
        for number in range(1, reaches + 1):
            row = {"person": person, "reach": number, "mode": mode, "error 0.5": 0.1}
            for f in (0.25, 0.5, 0.75, 0.9):
                count += 1
                row[f"covered {f:g}"] = covered_first if number == 1 else count % 10 < 10 * covered_later
            for f in (0.25, 0.5):
                row[f"forecast covered {f:g}"] = count % 10 < 10 * forecast_later
                count += 1
            out.append(row)
    return out


def test_the_targets_say_which_people_the_bands_hold(calibration):
    text = calibration.people_markdown(rows("P", True, 0.9, 0.9) + rows("Q", False, 1.0, 1.0))
    lines = {line.split(" | ")[0]: line for line in text.splitlines()}
    assert lines["| P"].split(" | ")[2] == "100 %" and lines["| Q"].split(" | ")[2] == "0 %"
    assert "endpoint's 95 % region holds 85–98 % (every person) |" in text
    assert "1 of 2 people inside | no |" in text                        # Q's regions hold everything: too wide
    assert "(pooled over people) | 50 % | no |" in text                 # one first reach of two held
    only_p = calibration.people_markdown(rows("P", True, 0.9, 0.9))
    assert only_p.count("1 of 1 people inside | yes |") == 2 and "| 100 % | no |" in only_p
