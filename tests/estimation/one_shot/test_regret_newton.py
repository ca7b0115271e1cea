"""Newton's method on the regret (comanip.estimation.one_shot.regret_newton.minimize_regret) on the planar point mass, against the
regret evaluated by brute force: R(g) = Jc(g) - V*(g), both plans solved by IPOPT on the reach problem's CasADi
expressions, Jc held to the observed state."""

import casadi as ca
import numpy as np
import pytest

from comanip.estimation.observation import observed_rows
from comanip.estimation.one_shot.regret_newton import minimize_regret
from comanip.estimation.one_shot.regret_system import RegretPoint, RegretSystem
from comanip.optim import Status

OBSERVED_STEP = 9
WIDTH = 0.02


@pytest.fixture(scope="module")
def reach(planar_planner):
    """The planar planner, its regret system, the plan to a true goal and IPOPT's regret R(g) (normalised J)."""
    problem = planar_planner.problem
    tau = ca.vec(problem.tau)
    f = problem.objective / -problem.best_objective
    parameters = ca.vertcat(problem.s0, problem.goal, problem.width)
    options = {"ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-12}, "print_time": False}
    free = ca.nlpsol("regret_free", "ipopt", {"x": tau, "p": parameters, "f": f}, options)
    held = ca.nlpsol("regret_held", "ipopt", {"x": tau, "p": parameters, "f": f, "g": problem.means[OBSERVED_STEP]}, options)
    start = np.zeros(4)

    def regret(goal, observed, warm):
        p = np.r_[start, goal, WIDTH]
        value_s = float(free(x0=warm, p=p)["f"])
        value_c = float(held(x0=warm, p=p, lbg=observed, ubg=observed)["f"])
        return value_c - value_s

    goal = np.array([0.3, 0.06])
    plan = planar_planner.solve(start, goal, WIDTH)
    return planar_planner, RegretSystem(planar_planner), start, goal, plan, regret


def _solve(reach, observed, from_goal):
    planner, system, start, _, _, _ = reach
    model = planner.model
    rows = observed_rows(model, OBSERVED_STEP)
    tau = planner.solve(start, from_goal, WIDTH).torque.ravel()
    point = RegretPoint(tau.copy(), np.zeros(len(rows)), tau.copy(), np.asarray(from_goal, dtype=float))
    return minimize_regret(system, point, start, observed, OBSERVED_STEP, rows, None, WIDTH, observed_position=observed[:model.n],
                        tolerance=1e-9, max_iterations=60, step_fraction=0.5, expired=lambda: False)


def test_an_exact_observation_of_a_plan_gives_back_its_goal(reach):
    """The regret is zero at the goal a plan was made for and positive elsewhere: from a goal 6 cm away the
    iteration ends on the plan's goal with zero regret, both inner plans equal to the plan."""
    _, _, _, goal, plan, _ = reach
    result = _solve(reach, plan.mean[OBSERVED_STEP][:4], goal + np.array([-0.05, 0.035]))
    assert result.status == Status.SOLVED, result.message
    np.testing.assert_allclose(result.x.goal, goal, atol=1e-6)
    assert abs(result.fun) < 1e-9
    np.testing.assert_allclose(result.x.tau_c, plan.torque.ravel(), atol=1e-4 * np.abs(plan.torque).max())
    np.testing.assert_allclose(result.x.tau_s, result.x.tau_c, atol=1e-4 * np.abs(plan.torque).max())


def test_the_regret_at_the_solution_is_the_brute_force_regret_and_a_local_minimum_of_it(reach, rng):
    """A perturbed observation (no plan passes through it): the regret minimize_regret reports equals IPOPT's
    Jc - V* at its goal, and IPOPT's regret 2 mm away along either axis is no lower."""
    _, _, _, goal, plan, regret = reach
    observed = plan.mean[OBSERVED_STEP][:4] + np.r_[rng.normal(scale=0.004, size=2), rng.normal(scale=0.02, size=2)]
    result = _solve(reach, observed, goal)
    assert result.status == Status.SOLVED, result.message
    found = result.x.goal
    warm = result.x.tau_s
    at_solution = regret(found, observed, warm)
    assert result.fun == pytest.approx(at_solution, rel=1e-6, abs=1e-10)
    assert at_solution > 0
    for shift in (np.array([0.002, 0.0]), np.array([0.0, 0.002])):
        for sign in (1, -1):
            assert regret(found + sign * shift, observed, warm) >= at_solution - 1e-10
