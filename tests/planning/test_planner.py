"""The planner: gradients, plans from varied starts, status handling, bad input."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import comanip
from comanip.belief import end_effector_belief, propagate_belief
from comanip.objectives import GoalReward, discount_weights, reach_objective
from comanip.planning.reach_parameters import ReachParameters


def test_objective_gradient_matches_finite_differences(planar_planner, rng):
    """The gradient the planner's solver uses (compiled C) against central differences of the SPEC §4 J."""
    problem, curvature = planar_planner.problem, planar_planner.curvature
    p = ReachParameters(np.zeros(4), [0.3, 0.0], 0.02)
    x = planar_planner.solve(np.zeros(4), [0.3, 0.0], 0.02).torque.ravel() + rng.normal(scale=0.5, size=60)
    g = curvature.evaluate(x, p).gradient
    J = lambda v: problem.objective_value(v, p.start, p.goal, p.width) / curvature.normaliser(p.width)  # noqa: E731
    eps = 1e-6
    fd = np.array([(J(x + eps * e) - J(x - eps * e)) / (2 * eps) for e in np.eye(60)])
    np.testing.assert_allclose(g, fd, rtol=1e-5, atol=1e-7 * np.abs(g).max())


def test_plan_objective_is_the_spec_objective(planar_planner):
    model = planar_planner.model
    plan = planar_planner.solve(np.zeros(4), [0.3, 0.0], 0.02)
    mean, cov = propagate_belief(model.body, model.h, model.kappa, plan.start, plan.torque, model.noise)
    ee_mean, ee_cov = end_effector_belief(model.body, mean, cov)
    J = reach_objective(ee_mean, ee_cov, plan.torque, plan.goal, 0.02, discount_weights(model.gamma, model.H), model.nu,
                        GoalReward.of(model))
    assert plan.objective == pytest.approx(J, rel=1e-9)
    np.testing.assert_allclose(plan.mean, mean, atol=1e-12)


@pytest.mark.parametrize("start", [[0, 0, 0, 0], [0.1, -0.1, 0, 0], [-0.2, 0.1, 0, 0], [0, 0, 0.5, 0], [0, 0, -0.3, 0.2]])
def test_plans_from_varied_starts_reach_the_goal(planar_planner, start):
    goal = np.array([0.3, 0.0])
    plan = planar_planner.solve(start, goal, 0.02)
    assert plan.success, plan.message
    assert plan.final_error < 0.02
    assert plan.ee_speed[-1] < 0.05 * plan.ee_speed.max()
    # the plan beats doing nothing: J of zero torques from the same start (a warm start from zero torques is no
    # such check: zero torques are a stationary point of J that the solver may stay at)
    nothing = planar_planner.problem.objective_value(np.zeros_like(plan.torque), np.asarray(start, float), goal, 0.02)
    assert plan.objective < nothing


def test_cartesian_plan_reaches_goal_and_warm_start_agrees(cartesian_planner):
    goal = np.array([0.35, -0.1, 0.15])
    cold = cartesian_planner.solve(np.zeros(6), goal, 0.05)
    warm = cartesian_planner.solve(np.zeros(6), goal + 0.01, 0.05, warm_start=cold)
    assert cold.success and warm.success
    assert cold.final_error < 0.05 and warm.final_error < 0.05
    again = cartesian_planner.solve(np.zeros(6), goal, 0.05, warm_start=warm)
    assert again.objective == pytest.approx(cold.objective, rel=1e-4)


def test_wall_time_budget_returns_a_finite_plan(cartesian_planner):
    plan = cartesian_planner.solve(np.zeros(6), [0.4, 0.2, 0.0], 0.005, max_wall_time=1e-3)
    assert plan.status == "max_wall_time" and not plan.success
    assert np.all(np.isfinite(plan.torque)) and np.isfinite(plan.objective)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        (dict(start=np.zeros(3)), "start"),
        (dict(start=[0, 0, np.nan, 0]), "start"),
        (dict(goal=[0.3]), "goal"),
        (dict(goal=[np.inf, 0]), "goal"),
        (dict(width=0.0), "width"),
        (dict(width=-0.01), "width"),
        (dict(width=float("nan")), "width"),
        (dict(warm_start=np.zeros((3, 2))), "warm_start"),
        (dict(max_wall_time=-1.0), "max_wall_time"),
    ],
)
def test_bad_solve_input_names_the_argument(planar_planner, kwargs, word):
    args = dict(start=np.zeros(4), goal=[0.3, 0.0], width=0.02) | kwargs
    with pytest.raises(ValueError, match=word):
        planar_planner.solve(**args)


@pytest.mark.parametrize("field, value", [("H", 0), ("H", -5), ("H", 2.5), ("h", -0.01), ("h", 0.0), ("gamma", 1.5),
                                          ("kappa", -1.0), ("nu", float("nan")), ("width", 0.0), ("noise", "pink"),
                                          ("goal_covariance", "var"), ("discount", "linear")])
def test_bad_model_parameters_raise_before_building(field, value):
    with pytest.raises(ValueError, match=field):
        comanip.presets.planar().replace(**{field: value})


def test_unknown_preset():
    with pytest.raises(ValueError, match="preset"):
        comanip.presets.load("planarr")


def test_preset_yaml_round_trip(tmp_path):
    model = comanip.presets.cartesian().replace(kappa=0.02, noise="per_channel")
    loaded = comanip.presets.load(comanip.presets.save(model, tmp_path / "m.yaml"))
    assert loaded.config() == model.config()
    assert (loaded.n, loaded.d, loaded.H, loaded.h) == (3, 3, 50, 0.055)
    np.testing.assert_allclose(loaded.M, 2 * np.eye(3))


def test_two_threads_with_separate_planners_plan_as_one_thread():
    """Planners share no state: two threads, each with its own planner, return the plans one thread does."""
    model = comanip.presets.planar()
    goals = [np.array([0.3, 0.0]), np.array([0.1, 0.25]), np.array([-0.2, 0.1])]

    def plan_all(planner):
        return [planner.solve(np.zeros(4), goal, 0.02) for goal in goals]

    expected = plan_all(comanip.Planner(model))
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(plan_all, [comanip.Planner(model), comanip.Planner(model)]))
    for plans in results:
        for plan, reference in zip(plans, expected):
            assert (plan.status, plan.iterations) == (reference.status, reference.iterations)
            np.testing.assert_array_equal(plan.torque, reference.torque)
