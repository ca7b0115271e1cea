"""A plan as the rest motion: through the plan's points at its times, holding its first and last points outside."""

import dataclasses

import numpy as np
import pytest

import comanip
from comanip.estimation.model_reaches.reach_timing import ReachTiming, timed_plan
from comanip.simulation.rest_trajectory import RestTrajectory


@pytest.mark.parametrize("timing", [None, ReachTiming(0.3, 0.5)])
def test_the_rest_passes_through_the_plan_and_holds_its_ends(timing):
    model = comanip.presets.arm()
    plan = comanip.Planner(model).solve(np.zeros(model.state_size), [0.2, 0.1, 0.0])
    if timing is not None:                                                       # the same reach played later and slower
        timed = timed_plan(plan.mean, plan.cov, plan.torque, model.h, model.n, timing)
        plan = dataclasses.replace(plan, t=timed.t, ee_mean=timed.mean[:, :3], ee_velocity=timed.mean[:, 3:6])
    dt = 0.001
    rest = RestTrajectory.from_plan(plan, 0.0, dt, plan.t[-1] + 0.2)
    for k in range(0, len(plan.t), 7):
        if plan.t[k] >= 0:
            np.testing.assert_allclose(rest(plan.t[k])[0], plan.ee_mean[k], atol=2e-3 * np.abs(plan.ee_mean).max())
    before = rest(0.5 * plan.t[0])                                               # before the plan starts: its start, still
    np.testing.assert_allclose(before[0], plan.ee_mean[0], atol=1e-12)
    np.testing.assert_array_equal(before[1], 0.0)
    after = rest(plan.t[-1] + 0.1)
    np.testing.assert_allclose(after[0], plan.ee_mean[-1], atol=1e-12)
    np.testing.assert_array_equal(after[1], 0.0)
