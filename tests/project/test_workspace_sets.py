"""The sampled workspace sets the solve-time benchmarks read (benchmarks/workspace/): what their script draws from its
seed, and inside the ranges it promises."""


import numpy as np
import pytest

import comanip
from tests.project.benchmark_scripts import load_benchmark


def _workspace():
    """benchmarks/workspace.py as a module."""
    return load_benchmark("workspace")


@pytest.mark.parametrize("preset", ["planar", "human_cartesian", "franka_rest"])
def test_a_stored_set_is_what_its_seed_draws_and_lies_in_its_ranges(preset):
    workspace = _workspace()
    model = comanip.presets.load(preset)
    stored = workspace.load(preset)
    draw = workspace.point_mass_problems if model.body.is_linear else workspace.arm_problems
    for kept, drawn in zip(stored, draw(model, len(stored))):
        for field in ("start", "goal", "warm_goal"):
            np.testing.assert_allclose(getattr(kept, field), getattr(drawn, field), rtol=0, atol=1e-12)
        assert kept.width == pytest.approx(drawn.width, abs=1e-15)
    home = model.body.home_position
    hand = np.asarray(model.body.kinematics_function(home)[0]).ravel()
    low, high = workspace.POINT_MASS_DISTANCES if model.body.is_linear else workspace.ARM_DISTANCES
    for problem in stored:
        assert low <= np.linalg.norm(problem.goal - hand) <= high
        assert workspace.WIDTHS[0] <= problem.width <= workspace.WIDTHS[1]
        assert 0.0 <= problem.speed <= workspace.TOP_SPEED
        assert np.all(np.abs(problem.warm_goal - problem.goal) <= workspace.WARM_MOVE)
        np.testing.assert_array_equal(problem.start[: model.n], home)
    moving = sum(problem.moving for problem in stored)
    assert 0 < moving < len(stored)  # both kinds of start
