import os
import tempfile
from pathlib import Path

import numpy as np
import pytest

import comanip


def pytest_configure(config):
    # compiled functions go to a test cache in the temporary folder, never the user's ~/.cache/comanip; it
    # is kept between runs (the Panda's terms take minutes to compile) unless COMANIP_CACHE_DIR says otherwise
    os.environ.setdefault("COMANIP_CACHE_DIR", str(Path(tempfile.gettempdir()) / "comanip-test-cache"))


@pytest.fixture(scope="session")
def planar_planner():
    return comanip.Planner(comanip.presets.planar())


@pytest.fixture(scope="session")
def cartesian_planner():
    return comanip.Planner(comanip.presets.cartesian())


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def activation_planner():
    """The planar preset with two 40 ms muscle activation stages: state [q; qdot; a_1; a_2] (8,)."""
    return comanip.Planner(comanip.presets.planar().replace(activation=(0.04, 0.04)))


def pytest_terminal_summary(terminalreporter):
    """Report how many generated inputs the fuzz suite (tests/test_fuzz.py) tried, when it ran."""
    import sys

    fuzz = sys.modules.get("test_fuzz") or sys.modules.get("tests.test_fuzz")
    if fuzz is not None and fuzz.FUZZ_COUNT["inputs"]:
        terminalreporter.write_line(f"fuzz: {fuzz.FUZZ_COUNT['inputs']} generated inputs tried")
