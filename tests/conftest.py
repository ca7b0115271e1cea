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
