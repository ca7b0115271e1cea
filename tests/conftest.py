import numpy as np
import pytest

import comanip


@pytest.fixture(scope="session")
def planar_planner():
    return comanip.Planner(comanip.presets.planar())


@pytest.fixture(scope="session")
def cartesian_planner():
    return comanip.Planner(comanip.presets.cartesian())


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
