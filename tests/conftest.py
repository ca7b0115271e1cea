import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import comanip

# Hypothesis: in CI (CI=true) every run draws the same inputs (derandomized, no example database), so a red run
# is the code's fault and reproduces anywhere; elsewhere each run draws new inputs and the database in
# .hypothesis/ replays a failure until it is fixed. HYPOTHESIS_PROFILE=ci (or dev) chooses explicitly.
settings.register_profile("ci", derandomize=True, database=None, deadline=None, print_blob=True,
                          suppress_health_check=list(HealthCheck))
settings.register_profile("dev", deadline=None, print_blob=True, suppress_health_check=list(HealthCheck))
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") == "true" else "dev"))


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
    """Report the Hypothesis profile and how many generated inputs the fuzz suite (tests/project/test_fuzz.py)
    tried, when it ran."""
    import sys

    fuzz = sys.modules.get("tests.project.test_fuzz")
    if fuzz is not None and fuzz.FUZZ_COUNT["inputs"]:
        terminalreporter.write_line(f"fuzz: {fuzz.FUZZ_COUNT['inputs']} generated inputs tried "
                                    f"(hypothesis profile {settings.get_current_profile_name()!r})")
