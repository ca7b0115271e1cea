"""Plans, estimates and posteriors of a fixed set of problems equal those of the stored reference code
(tests/data/make_reference_results.py wrote them): refactoring the solvers must not change their results.

Objectives agree to 1e-9 relative, normalised regrets to 1e-9, goals to 1e-9 m, probabilities to 1e-9 and
statuses exactly. Torques agree to 1e-3 of their largest magnitude: near an optimum the objective is flat in
some directions, so rounding that differs between processors (BLAS kernels) moves converged torques while the
objective stays equal to 1e-9 (planar: 1.6e-5 of their size; the paper Panda preset's last warm steps, in a
flat valley: 2.4e-4). Iteration counts may fall, and rise by at
most a tenth (the same rounding changes the Panda's cold path: 174 instead of 169 iterations on one processor).
Those tolerances hold for the tested versions of the numerical libraries (constraints.txt); with others (the oldest
supported set, constraints-oldest.txt) their own rounding moves the converged points further, and objectives, goals
and probabilities agree to 1e-6.
"""

import importlib.util
import re
from importlib import metadata
from pathlib import Path

import numpy as np
import pytest

DATA = Path(__file__).parents[1] / "data"
NUMERICAL_LIBRARIES = ("numpy", "scipy", "casadi")
"""The libraries whose rounding the stored results were made with."""


def _tested_versions() -> bool:
    """Whether :data:`NUMERICAL_LIBRARIES` are installed at the versions constraints.txt pins."""
    pins = dict(re.findall(r"^([A-Za-z0-9_.-]+)==(\S+)$", (DATA.parents[1] / "constraints.txt").read_text(), re.M))
    return all(metadata.version(name) == pins[name] for name in NUMERICAL_LIBRARIES)


TOLERANCE = 1e-9 if _tested_versions() else 1e-6
TORQUE_TOLERANCE = 1e-3


def _reference_module():
    spec = importlib.util.spec_from_file_location("make_reference_results", DATA / "make_reference_results.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _assert_equal_results(stored, computed: dict) -> None:
    assert sorted(stored.files) == sorted(computed)
    for name in stored.files:
        expected, actual = stored[name], np.asarray(computed[name])
        quantity = name.rsplit("/", 1)[1]
        if quantity == "status":
            assert actual == expected, name
        elif quantity == "iterations":
            assert actual <= max(expected * 1.1, expected + 2), (name, int(actual), int(expected))
        elif quantity == "objective":
            np.testing.assert_allclose(actual, expected, rtol=TOLERANCE, atol=0, err_msg=name)
        elif quantity == "regret":  # normalised, in [0, 1], and ~1e-13 at an exact estimate: absolute
            np.testing.assert_allclose(actual, expected, rtol=0, atol=TOLERANCE, err_msg=name)
        else:
            tolerance = TORQUE_TOLERANCE * max(1.0, float(np.max(np.abs(expected)))) if quantity == "torque" else TOLERANCE
            np.testing.assert_allclose(actual, expected, rtol=0, atol=tolerance, err_msg=name)


def test_point_mass_results_equal_the_reference():
    module = _reference_module()
    _assert_equal_results(np.load(module.PATH), module.reference_results())


@pytest.mark.slow
def test_franka_results_equal_the_reference():
    module = _reference_module()
    _assert_equal_results(np.load(module.FRANKA_PATH), module.franka_reference_results())
