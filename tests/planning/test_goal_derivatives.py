"""The goal derivatives of the planner's Newton terms (what the goal estimator's Newton method uses):
dJ/dg, d²J/dtau dg and d²J/dg² against central differences of the exact objective and gradient (point
masses) and against CasADi's exact Hessian of the expanded rollout (the Panda on a short horizon)."""

import casadi as ca
import numpy as np
import pytest

import comanip
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.curvature import ReachCurvature
from comanip.planning.linearised_curvature import LinearisedCurvature
from comanip.planning.reach_problem import ReachProblem


@pytest.mark.parametrize("preset, goal", [("planar", [0.25, -0.1]), ("cartesian", [0.2, 0.15, -0.1])])
def test_point_mass_goal_derivatives_match_finite_differences(request, preset, goal):
    planner = request.getfixturevalue(f"{preset}_planner")
    model = planner.model
    curvature = ReachCurvature(planner.problem)
    start, goal = np.zeros(2 * model.n), np.array(goal)
    # torques of a plan to a nearby goal: the reward is far from underflow and the goal terms are sizeable
    tau = planner.solve(start, goal + 0.02).torque.ravel()

    def terms(g):
        evaluation = curvature.evaluate(tau, ReachParameters(start, g, model.width))
        return evaluation.f, evaluation.gradient, curvature.goal_derivatives(evaluation.data).gradient

    derivatives = curvature.goal_derivatives(curvature.evaluate(tau, ReachParameters(start, goal, model.width)).data)
    grad_g, cross, hess_gg = derivatives.gradient, derivatives.cross, derivatives.hessian
    eps = 1e-6
    differences = [[(a - b) / (2 * eps) for a, b in zip(terms(goal + eps * e), terms(goal - eps * e))] for e in np.eye(model.d)]
    fd_grad_g = np.array([row[0] for row in differences])
    fd_cross = np.column_stack([row[1] for row in differences])
    fd_hess_gg = np.array([row[2] for row in differences])
    np.testing.assert_allclose(grad_g, fd_grad_g, rtol=1e-6, atol=1e-8 * np.abs(grad_g).max())
    np.testing.assert_allclose(cross, fd_cross, atol=1e-6 * np.abs(cross).max())
    np.testing.assert_allclose(hess_gg, fd_hess_gg, atol=1e-6 * np.abs(hess_gg).max())
    assert np.abs(cross).max() > 1e-3 * np.abs(grad_g).max()  # the check is not on a vanishing term


def test_panda_goal_derivatives_against_casadi(rng):
    """dJ/dg and d²J/dg² are exact; d²J/dtau dg carries the Hessian's approximation (A_i, B_i held along
    the path) in its covariance rows only: within 1e-3 of CasADi's, where a wrong index is off by order one."""
    model = comanip.presets.load("franka").replace(H=3)
    problem = ReachProblem(model)
    curvature = LinearisedCurvature(problem, compile=False)
    start = np.r_[model.body.home_position + rng.normal(scale=0.1, size=7), rng.normal(scale=0.2, size=7)]
    tau = rng.normal(scale=2.0, size=7 * model.H)
    goal = np.asarray(model.body.kinematics_function(start[:7])[0]).ravel() + rng.uniform(-0.03, 0.03, 3)
    derivatives = curvature.goal_derivatives(curvature.evaluate(tau, ReachParameters(start, goal, model.width)).data)
    grad_g, cross, hess_gg = derivatives.gradient, derivatives.cross, derivatives.hessian

    x = ca.vertcat(ca.vec(problem.tau), problem.goal)
    hessian, gradient = ca.hessian(problem.objective / -problem.best_objective, x)
    exact = ca.Function("exact", [ca.vec(problem.tau), problem.goal, problem.s0, problem.width], [gradient, hessian])
    gradient, hessian = (np.asarray(v) for v in exact(tau, goal, start, model.width))
    Hn = tau.size
    np.testing.assert_allclose(grad_g, gradient[Hn:].ravel(), rtol=1e-10, atol=1e-12 * np.abs(grad_g).max())
    np.testing.assert_allclose(hess_gg, hessian[Hn:, Hn:], atol=1e-10 * np.abs(hess_gg).max())
    assert np.linalg.norm(cross - hessian[:Hn, Hn:], 2) < 1e-3 * np.linalg.norm(hessian[:Hn, Hn:], 2)
