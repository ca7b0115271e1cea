"""Goal estimation on the Franka preset (7-DOF Panda: approximate Hessian, joint limits that bind in most
reaches): a plan observed at t_obs = 0.2 s gives back its goal."""

import numpy as np
import pytest

import comanip
from comanip.estimation import GoalEstimator
from comanip.estimation.observation import observation_step
from comanip.planning.path_limits import PathLimits

pytestmark = pytest.mark.slow  # the Panda: compiled terms, minutes on a first run

T_OBS = 0.2


@pytest.fixture(scope="module")
def franka_estimator():
    return GoalEstimator(comanip.presets.franka())


def test_franka_observed_plans_give_back_their_goals(franka_estimator):
    """Three goals 0.2–0.25 m from the ready pose in different directions. Each hidden plan (warm-started
    from the one before, as a robot tracking a person would) is observed at 0.2 s; the estimate starts
    from the plan to a prior goal 3–4 cm off (no regulariser, so the observation alone decides)."""
    model = franka_estimator.model
    planner = franka_estimator.planner
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    home = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    n_o = observation_step(model, T_OBS)
    hidden = None
    for offset, prior_offset in [([0.0, 0.2, 0.0], [0.02, 0.02, -0.02]), ([0.0, -0.25, 0.0], [-0.02, 0.02, 0.02]),
                                 ([0.1, 0.1, -0.15], [0.02, -0.02, 0.02])]:
        goal = home + offset
        hidden = planner.solve(start, goal, warm_start=hidden)
        assert hidden.success, hidden.message
        prior_plan = planner.solve(start, goal + prior_offset, warm_start=hidden)
        estimate = franka_estimator.estimate(start, hidden.mean[n_o], T_OBS, warm_start=prior_plan)
        distance = np.linalg.norm(offset)
        print(f"\n{offset}: {estimate.status}, {estimate.iterations} iterations, {estimate.solve_time:.2f} s, "
              f"error {1e3 * np.linalg.norm(estimate.goal - goal):.2f} mm")
        assert estimate.success, estimate.message
        assert np.linalg.norm(estimate.goal - goal) < 0.1 * distance
        assert np.abs(estimate.observation_residual).max() < 1e-4
        # the predicted remainder follows the hidden plan (end effector, m)
        assert np.abs(estimate.ee_mean[n_o:] - hidden.ee_mean[n_o:]).max() < 0.1 * distance


def test_franka_estimate_from_the_hidden_plan_is_exact(franka_estimator):
    """Both plans keep the binding joint limits as the planner does, so the hidden plan itself solves the
    regret's conditions: warm-started there, the estimate stays on its goal (without the limits the
    unconstrained plan to that goal differs, and the estimate moves off by millimetres)."""
    model = franka_estimator.model
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    home = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    goal = home + [0.0, -0.25, 0.0]
    hidden = franka_estimator.planner.solve(start, goal)
    assert np.max(PathLimits.of(model).constraints(hidden.mean)) > -1e-6  # a limit binds in this reach
    n_o = observation_step(model, T_OBS)
    estimate = franka_estimator.estimate(start, hidden.mean[n_o], T_OBS, warm_start=hidden)
    assert estimate.success, estimate.message
    assert np.linalg.norm(estimate.goal - goal) < 1e-5


def test_franka_rejects_the_paper_method_before_any_solve(franka_estimator):
    """Eq. 11 by IPOPT needs CasADi's exact Hessian of the expanded Panda problem: refused up front."""
    start = np.r_[franka_estimator.model.body.home_position, np.zeros(7)]
    with pytest.raises(ValueError, match="method 'paper'"):
        franka_estimator.estimate(start, start, T_OBS, method="paper")
