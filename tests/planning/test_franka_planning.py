"""Planning for the 7-DOF Panda: plans across the workspace within the joint limits, unreachable goals,
and the derivatives the Newton method uses (exact gradient and mean sensitivities, approximate Hessian)."""


import casadi as ca
import numpy as np
import pytest

import comanip
from comanip.planning.linearised_curvature import LinearisedCurvature
from comanip.planning.path_limits import LIMIT_TOLERANCE
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_parameters import ReachParameters

pytestmark = pytest.mark.slow  # the Panda: compiled terms, minutes on a first run


@pytest.fixture(scope="module")
def franka_planner():
    return comanip.Planner(comanip.presets.franka())


@pytest.fixture(scope="module")
def franka_rest_planner():
    return comanip.Planner(comanip.presets.load("franka_rest"))


@pytest.fixture(scope="module")
def short_franka():
    """The Franka preset with a 5-step horizon: small enough for CasADi's exact derivatives."""
    model = comanip.presets.load("franka").replace(H=5)
    problem = ReachProblem(model)
    return model, problem, LinearisedCurvature(problem, compile=False)


def _point(model, rng):
    start = np.r_[model.body.home_position + rng.normal(scale=0.1, size=7), rng.normal(scale=0.2, size=7)]
    tau = rng.normal(scale=2.0, size=7 * model.H)
    goal = np.asarray(model.body.kinematics_function(start[:7])[0]).ravel() + rng.uniform(-0.1, 0.1, 3)
    return tau, ReachParameters(start, goal, 0.05)


def test_gradient_and_mean_sensitivities_are_exact(short_franka, rng):
    """The compiled gradient against central differences of the SPEC §4 J (CasADi's expanded rollout, an
    independent construction), and d mu_i / d tau against CasADi's Jacobian of the mean rollout."""
    model, problem, curvature = short_franka
    tau, p = _point(model, rng)
    evaluation = curvature.evaluate(tau, p)
    f, g, data = evaluation.f, evaluation.gradient, evaluation.data
    J = lambda x: problem.objective_value(x, p.start, p.goal, p.width) / curvature.normaliser(p.width)  # noqa: E731
    assert f == pytest.approx(J(tau), rel=1e-12)
    eps = 1e-6
    fd = np.array([(J(tau + eps * e) - J(tau - eps * e)) / (2 * eps) for e in np.eye(tau.size)])
    np.testing.assert_allclose(g, fd, rtol=1e-5, atol=1e-7 * np.abs(g).max())
    means = ca.Function("means", [ca.vec(problem.tau), problem.s0], [ca.horzcat(*problem.means)])
    exact = np.asarray(ca.Function("dmu", [ca.vec(problem.tau), problem.s0],
                                   [ca.jacobian(ca.vec(means(ca.vec(problem.tau), problem.s0)), ca.vec(problem.tau))])(tau, p.start))
    T = curvature.mean_sensitivities(data)  # (H+1, 2n, H, n): rows (i, state entry), columns (k, joint)
    np.testing.assert_allclose(T.reshape(-1, tau.size), exact, atol=1e-10 * np.abs(exact).max())


def test_structured_hessian_is_close_to_the_exact_one(short_franka, rng):
    """The approximation leaves out the dynamics' curvature only: on a short horizon it is within 10 % of
    CasADi's exact Hessian (spectral norm); a wrong index or sign would be off by order one."""
    model, problem, curvature = short_franka
    x = ca.vec(problem.tau)
    f = problem.objective / -problem.best_objective
    exact = ca.Function("H", [x, problem.s0, problem.goal, problem.width], [ca.hessian(f, x)[0]])
    for _ in range(2):
        tau, p = _point(model, rng)
        H_exact = np.asarray(exact(tau, p.start, p.goal, p.width))
        H = curvature.hessian(curvature.evaluate(tau, p).data)
        assert np.linalg.norm(H - H_exact, 2) < 0.1 * np.linalg.norm(H_exact, 2)


@pytest.mark.parametrize("noise", ["isotropic", "per_channel", "rank_one"])
def test_condensed_hessian_equals_the_sum_over_steps(noise, rng):
    """The assembly (backward recursion for the state cost, contracted noise rows) against the plain sum
    Σ_i Z_iᵀ ∇²phi_i Z_i + T_iᵀ W_i T_i over explicit rows Z_i, the noise rows built one torque at a time
    from central differences of N(tau) (exact: N is quadratic), plus the noise's own curvature and effort."""
    from comanip.belief.noise import noise_covariance

    model = comanip.presets.load("franka").replace(H=6, noise=noise)
    curvature = LinearisedCurvature(ReachProblem(model), compile=False)
    tau, p = _point(model, rng)
    data = curvature.evaluate(tau, p).data
    n, d, H = 7, 3, model.H
    pieces = curvature.pieces(data)
    J, Q, phi_grad, W, dvech = pieces.J, pieces.phi_hess, pieces.phi_grad, pieces.kinematic_hessian, pieces.dvech
    T = curvature.mean_sensitivities(data)[:, :n].reshape(H + 1, n, H * n)
    triangle = [(a, b) for b in range(d) for a in range(b + 1)]
    vech = lambda S: np.array([S[a, b] for a, b in triangle])  # noqa: E731
    nz = d + len(triangle)
    N_of = lambda t: noise_covariance(t, model.kappa, noise)  # noqa: E731
    unit = np.eye(n)
    E = [[(N_of(t + e) - N_of(t - e)) / 2 for e in unit] for t in tau.reshape(H, n)]  # dN/dtau_j at tau_k
    second = [[(N_of(unit[j] + unit[m]) - N_of(unit[j] - unit[m])) / 2 for m in range(n)] for j in range(n)]
    expected = np.zeros((H * n, H * n))
    for i in range(H + 1):
        J_i, Q_i = J[:, i * n:(i + 1) * n], Q[:, i * nz:(i + 1) * nz]
        G = J_i @ T[i]
        N = np.array([vech(G[:, k * n:(k + 1) * n] @ E[k][j] @ G[:, k * n:(k + 1) * n].T)
                      for k in range(H) for j in range(n)]).T
        Z = np.vstack([G, dvech[:, i * n:(i + 1) * n] @ T[i] + N])
        expected += Z.T @ Q_i @ Z + T[i].T @ W[:, i * n:(i + 1) * n] @ T[i]
        Lambda = np.zeros((d, d))
        for (a, b), g in zip(triangle, phi_grad[d:, i]):
            Lambda[a, b] = Lambda[b, a] = g if a == b else g / 2
        for k in range(H):
            G_k = G[:, k * n:(k + 1) * n]
            for j in range(n):
                for m in range(n):
                    expected[k * n + j, k * n + m] += np.sum(Lambda * (G_k @ second[j][m] @ G_k.T))
    expected += 2 * model.nu / curvature.normaliser(p.width) * np.eye(H * n)
    np.testing.assert_allclose(curvature.hessian(data), expected, rtol=0, atol=1e-12 * np.abs(expected).max())


SPEED_COST = dict(stop_weight=0.7, joint_velocity_weight=0.3)
"""Speed-cost weights for the derivative tests, (s/rad)² (larger than franka_rest's so the terms matter)."""


@pytest.fixture(scope="module")
def short_franka_rest():
    """A 3-step Franka problem with the speed cost, and the same problem without it."""
    model = comanip.presets.load("franka").replace(H=3, **SPEED_COST)
    problem = ReachProblem(model)
    bare = LinearisedCurvature(ReachProblem(model.replace(stop_weight=0.0, joint_velocity_weight=0.0)), compile=False)
    return model, problem, LinearisedCurvature(problem, compile=False), bare


def test_speed_cost_value_and_gradient_are_exact(short_franka_rest, rng):
    """f with the speed cost against the SPEC §4 J of CasADi's expanded rollout (which adds
    |J_best| (c_s E||qdot_H||² + c_v mean_i E||qdot_i||²)), the gradient against its central differences, and
    the cost itself against a NumPy rollout of the belief (an independent construction)."""
    from comanip.belief.propagation import propagate_belief

    model, problem, curvature, bare = short_franka_rest
    tau, p = _point(model, rng)
    evaluation = curvature.evaluate(tau, p)
    f, g = evaluation.f, evaluation.gradient
    J = lambda x: problem.objective_value(x, p.start, p.goal, p.width) / curvature.normaliser(p.width)  # noqa: E731
    assert f == pytest.approx(J(tau), rel=1e-12)
    mean, cov = propagate_belief(model.body, model.h, model.kappa, p.start, tau.reshape(model.H, 7), model.noise)
    energies = np.sum(mean[1:, 7:] ** 2, axis=1) + np.trace(cov[1:, 7:, 7:], axis1=1, axis2=2)
    expected = SPEED_COST["stop_weight"] * energies[-1] + SPEED_COST["joint_velocity_weight"] * energies.mean()
    assert f - bare.value(tau, p) == pytest.approx(expected, rel=1e-9)
    eps = 1e-6
    fd = np.array([(J(tau + eps * e) - J(tau - eps * e)) / (2 * eps) for e in np.eye(tau.size)])
    np.testing.assert_allclose(g, fd, rtol=1e-5, atol=1e-7 * np.abs(g).max())


def test_speed_cost_hessian_is_the_gauss_newton_term_and_close_to_the_exact_one(short_franka_rest, rng):
    """The speed cost's share of the structured Hessian equals its Gauss–Newton form along the mean,
    Σ_i 2 c_i T_v,iᵀ T_v,i + blockdiag_k Σ_i c_i <T_v,ikᵀ T_v,ik, ∂²N>, built from explicit rows (N's second
    derivatives by central differences, exact: N is quadratic); and it is within 10 % of CasADi's exact Hessian
    of the speed cost alone (the rest is the dynamics' curvature, left out as for the reward)."""
    from comanip.belief.noise import noise_covariance
    from comanip.objectives.reach_objective import velocity_cost

    model, problem, curvature, bare = short_franka_rest
    n, H = 7, model.H
    c = np.full(H + 1, SPEED_COST["joint_velocity_weight"] / H)
    c[0], c[-1] = 0.0, c[-1] + SPEED_COST["stop_weight"]
    unit = np.eye(n)
    N_of = lambda t: noise_covariance(t, model.kappa, model.noise)  # noqa: E731
    second = [[(N_of(unit[j] + unit[m]) - N_of(unit[j] - unit[m])) / 2 for m in range(n)] for j in range(n)]
    x = ca.vec(problem.tau)
    cost = velocity_cost([m[n:2 * n] for m in problem.means[1:]], [S[n:2 * n, n:2 * n] for S in problem.covs[1:]],
                         SPEED_COST["stop_weight"], SPEED_COST["joint_velocity_weight"])
    exact = ca.Function("speed_hessian", [x, problem.s0], [ca.hessian(cost, x)[0]])
    for _ in range(3):
        tau, p = _point(model, rng)
        data = curvature.evaluate(tau, p).data
        share = curvature.hessian(data) - bare.hessian(bare.evaluate(tau, p).data)
        Tv = curvature.mean_sensitivities(data)[:, n:].reshape(H + 1, n, H * n)
        expected = sum(2 * c[i] * Tv[i].T @ Tv[i] for i in range(H + 1))
        for k in range(H):
            S_k = sum(c[i] * Tv[i][:, k * n:(k + 1) * n].T @ Tv[i][:, k * n:(k + 1) * n] for i in range(H + 1))
            expected[k * n:(k + 1) * n, k * n:(k + 1) * n] += [[np.sum(S_k * second[j][m]) for m in range(n)] for j in range(n)]
        np.testing.assert_allclose(share, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
        H_exact = np.asarray(exact(tau, p.start))
        assert np.linalg.norm(share - H_exact, 2) < 0.1 * np.linalg.norm(H_exact, 2)


@pytest.mark.parametrize("offset", [[0.15, 0.1, -0.1], [0.0, -0.2, 0.1], [-0.1, 0.15, 0.15]])
def test_franka_rest_plans_end_at_rest_without_whipping(franka_rest_planner, offset):
    """The ``franka_rest`` preset (speed cost on): every joint ends slower than 0.05 rad/s and none runs at its
    speed limit once the hand has stopped. The paper's ``franka`` preset fails both on the first goal
    (test_paper_franka_plan_ends_moving)."""
    from comanip.analysis import settling_motion

    planner = franka_rest_planner
    model = planner.model
    start = np.r_[model.body.home_position, np.zeros(7)]
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + offset
    plan = planner.solve(start, goal)
    assert plan.success, (plan.status, plan.message)
    motion = settling_motion(model, plan)
    assert motion.final_joint_speed < 0.05
    assert motion.time_at_velocity_limit == 0.0


def test_paper_franka_plan_ends_moving(franka_planner):
    """What franka_rest removes: the paper's plan to [0.15, 0.1, -0.1] m from the ready pose keeps a wrist joint at
    its speed limit after the hand has stopped and ends with a joint faster than 1 rad/s."""
    from comanip.analysis import settling_motion

    model = franka_planner.model
    start = np.r_[model.body.home_position, np.zeros(7)]
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + [0.15, 0.1, -0.1]
    plan = franka_planner.solve(start, goal)
    motion = settling_motion(model, plan)
    assert plan.success and motion.final_joint_speed > 1.0 and motion.time_at_velocity_limit > 0.1


def test_starts_solved_side_by_side_give_the_plan_solved_one_after_another(franka_planner, monkeypatch):
    """The paper preset's cold solve runs its three starts on threads; each thread evaluates with its own buffers,
    so the plan, its objective and its iterations are those of the starts solved in turn, bit for bit."""
    from comanip.planning.solver_options import SolverOptions
    from comanip.planning.start_threads import StartThreads

    model = franka_planner.model
    start = np.r_[model.body.home_position, np.zeros(7)]
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + [0.1, -0.15, 0.1]
    threads_used = []
    map_on_threads = StartThreads.map
    monkeypatch.setattr(StartThreads, "map", lambda self, solve, starts: threads_used.append(self.threads)
                        or map_on_threads(self, solve, starts))
    side_by_side = comanip.Planner(model, SolverOptions(threads=3)).solve(start, goal)
    in_turn = comanip.Planner(model, SolverOptions(threads=1)).solve(start, goal)
    assert threads_used and set(threads_used) == {3}
    np.testing.assert_array_equal(side_by_side.torque, in_turn.torque)
    assert (side_by_side.objective, side_by_side.iterations, side_by_side.status) == \
        (in_turn.objective, in_turn.iterations, in_turn.status)


def test_a_budgeted_cold_search_on_threads_returns_its_best_plan_so_far(franka_planner):
    """Every start on its thread stops at the wall-time budget; the best plan so far comes back, finite, with status
    'max_wall_time' (a cold search of the paper preset takes several times this budget)."""
    model = franka_planner.model
    start = np.r_[model.body.home_position, np.zeros(7)]
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + [0.15, 0.1, -0.1]
    plan = franka_planner.solve(start, goal, max_wall_time=0.1)   # set-up alone can take most of 50 ms on a loaded machine
    assert plan.status == "max_wall_time" and not plan.success
    assert np.all(np.isfinite(plan.torque)) and np.isfinite(plan.objective) and plan.iterations > 0


def test_a_ranked_cold_search_abandons_starts_a_converged_start_beats():
    """With abandon_after one past the shortest start's iterations, the starts still running then are worse than
    the converged one (all three end on the same optimum here) and are abandoned: fewer iterations than the full
    search, the same plan's objective. 'all' keeps every start to the end whatever abandon_after says."""
    from comanip.planning.solver_options import SolverOptions
    from comanip.planning.reach_parameters import ReachParameters

    model = comanip.presets.franka()
    start = np.r_[model.body.home_position, np.zeros(7)]
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + [0.15, 0.1, -0.1]
    full = comanip.Planner(model, SolverOptions(cold_search="all", threads=1))
    params = ReachParameters(start, goal, model.width)
    starts = [full.solver.solve(guess, params) for guess in full.starts.searched_guesses(params)]
    shortest = min(result.nit for result in starts)
    assert max(result.nit for result in starts) > shortest + 1  # the case needs a start still running
    assert max(result.fun for result in starts) - min(result.fun for result in starts) < 1e-6 * abs(starts[0].fun)
    options = dict(abandon_after=shortest + 1, threads=1, arm_narrow_ratio=1e9)  # every start, as in the full search
    reference = full.solve(start, goal)
    searched = comanip.Planner(model, SolverOptions(**options)).solve(start, goal)
    assert searched.success and searched.iterations < reference.iterations
    assert searched.objective == pytest.approx(reference.objective, rel=1e-6)
    assert comanip.Planner(model, SolverOptions(cold_search="all", **options)).solve(start, goal).iterations == reference.iterations


def test_a_ranked_cold_search_leaves_out_the_worst_guess_only_for_a_narrow_goal():
    """Beyond arm_narrow_ratio widths a ranked cold search from rest without a reach library runs every minimum-jerk
    guess but the one of highest objective; nearer, from a moving start, and for 'all', every guess."""
    from comanip.planning.solver_options import SolverOptions
    from comanip.planning.reach_parameters import ReachParameters

    model = comanip.presets.franka()
    start = np.r_[model.body.home_position, np.zeros(7)]
    goal = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel() + [0.15, 0.1, -0.1]
    distance = float(np.linalg.norm([0.15, 0.1, -0.1]))
    planner = comanip.Planner(model, SolverOptions(threads=1))
    ratio = planner.options.arm_narrow_ratio
    narrow, near = (ReachParameters(start, goal, distance / (ratio * factor)) for factor in (2.0, 0.5))
    guesses = planner.starts.cold_guesses(narrow, planner.options.n_starts)
    worst = max(range(len(guesses)), key=lambda k: planner.starts.objective(guesses[k], narrow))
    kept = planner.starts.searched_guesses(narrow)
    assert len(kept) == len(guesses) - 1
    assert not any(np.array_equal(guess, guesses[worst]) for guess in kept)
    assert len(planner.starts.searched_guesses(near)) == len(guesses)
    moving = ReachParameters(np.r_[model.body.home_position, np.full(7, 0.1)], goal, narrow.width)
    assert len(planner.starts.searched_guesses(moving)) == len(guesses)
    full = comanip.Planner(model, SolverOptions(cold_search="all", threads=1))
    assert len(full.starts.searched_guesses(narrow)) == len(guesses)


def test_franka_plans_around_the_workspace_reach_their_goals_within_the_limits(franka_planner):
    """Ten goals around the ready pose (up to 0.2 m along each axis), visited in a tour and each
    warm-started from the plan to the one before, as a robot tracking a person would."""
    model = franka_planner.model
    body = model.body
    start = np.r_[body.home_position, np.zeros(7)]
    home = np.asarray(body.kinematics_function(body.home_position)[0]).ravel()
    offsets = [[0.15, 0.1, -0.1], [0.2, 0.15, -0.2], [0.1, 0.0, -0.2], [0.2, -0.2, -0.1], [0.2, -0.1, 0.0],
               [0.05, -0.15, 0.15], [0.15, 0.0, 0.15], [0.1, 0.2, 0.1], [-0.05, 0.2, 0.0], [0.0, -0.2, -0.15]]
    plan, fastest_joint = None, 0.0
    for offset in offsets:
        goal = home + offset
        plan = franka_planner.solve(start, goal, warm_start=plan)
        assert plan.success, (offset, plan.status, plan.message)
        assert plan.final_error < model.width
        q, qdot = plan.mean[1:, :7], plan.mean[1:, 7:]
        assert np.all(q <= body.q_max + LIMIT_TOLERANCE) and np.all(q >= body.q_min - LIMIT_TOLERANCE)
        assert np.all(np.abs(qdot) <= body.qdot_max + LIMIT_TOLERANCE)
        assert np.all(np.abs(plan.torque) <= body.tau_max + 1e-9)
        fastest_joint = max(fastest_joint, float(np.max(np.abs(qdot) / body.qdot_max)))
    # the reaches are fast enough for the velocity limits to bind: the working set was exercised
    assert fastest_joint > 0.99


@pytest.mark.parametrize("drop", [0.2, 0.25])
def test_cold_reach_along_a_joint_limit_converges(franka_planner, drop):
    """Reaching down from the ready pose, joint 4 runs along its lower limit for the second half of the
    reach. The solver once stalled there (a limit met to 3e-8 kept in the working set against a negative
    multiplier; the merit's penalty blocking every step) or kept the zero-reward plan of another start,
    570 mm from the goal, as its 'success'."""
    model = franka_planner.model
    body = model.body
    start = np.r_[body.home_position, np.zeros(7)]
    goal = np.asarray(body.kinematics_function(body.home_position)[0]).ravel() - [0.0, 0.0, drop]
    plan = franka_planner.solve(start, goal)
    assert plan.success, (plan.status, plan.message)
    assert plan.final_error < model.width
    assert np.min(plan.mean[1:, 3] - body.q_min[3]) < 1e-3  # the limit binds
    assert np.all(plan.mean[1:, :7] >= body.q_min - LIMIT_TOLERANCE)


def test_closed_loop_franka_replans_converge(franka_planner):
    """A closed-loop reach replans at every step from the noisy state, warm-started with the shifted plan:
    the real-time use. Before the solver's recovery steps a quarter of these replans ended 'failed'."""
    from comanip.execution import execute_receding_horizon

    body = franka_planner.model.body
    start = np.r_[body.home_position, np.zeros(7)]
    goal = np.asarray(body.kinematics_function(body.home_position)[0]).ravel() + [0.15, 0.1, -0.1]
    run = execute_receding_horizon(franka_planner, start, goal, steps=40, rng=np.random.default_rng(0))
    assert run.failed_replans <= 2
    assert np.linalg.norm(run.ee[-1] - goal) < franka_planner.model.width


@pytest.mark.parametrize("goal", [[1.5, 0.0, 0.3], [0.0, 0.0, -0.9]])
def test_unreachable_goal_returns_status_not_exception(franka_planner, goal):
    start = np.r_[franka_planner.model.body.home_position, np.zeros(7)]
    plan = franka_planner.solve(start, goal)
    assert not plan.success and plan.status == "unreachable"
    assert "beyond the goal width" in plan.message
    assert np.all(np.isfinite(plan.torque)) and np.isfinite(plan.objective) and plan.iterations == 0


def test_warm_solve_to_a_nearby_goal_needs_no_inverse_kinematics(franka_rest_planner, monkeypatch):
    """A warm solve checks reachability from the warm plan's final position (a few least-squares steps) and runs
    the inverse kinematics only when they do not reach the goal: not for a goal moved 4 cm, but for one out of
    reach, which is still 'unreachable'. The witness is always within the joint limits, even from a final
    position outside them."""
    planner = franka_rest_planner
    body = planner.model.body
    start = np.r_[body.home_position, np.zeros(7)]
    home = np.asarray(body.kinematics_function(body.home_position)[0]).ravel()
    plan = planner.solve(start, home + [0.15, 0.1, -0.1])
    calls = []
    full_inverse_kinematics = body.inverse_kinematics
    monkeypatch.setattr(body, "inverse_kinematics", lambda *args, **kwargs: calls.append(args) or full_inverse_kinematics(*args, **kwargs))
    nearby = planner.solve(start, home + [0.19, 0.12, -0.08], warm_start=plan)
    assert nearby.success and calls == []
    unreachable = planner.solve(start, [1.5, 0.0, 0.3], warm_start=nearby)
    assert unreachable.status == "unreachable" and len(calls) == 1
    outside = nearby.mean.copy()
    outside[-1, 3] = body.q_min[3] - 0.3  # joint 4 beyond its limit, the goal where that puts the hand
    goal = np.asarray(body.kinematics_function(outside[-1, :7])[0]).ravel()
    witness = planner.goal_joints(ReachParameters(start, goal, 0.05), near=outside[-1, :7])
    assert np.all(witness >= body.q_min) and np.all(witness <= body.q_max)


@pytest.mark.parametrize("offset", [[0.15, 0.1, -0.1], [0.0, -0.2, 0.1]])
def test_lazy_hessian_reaches_the_optimum_of_eager_assembly(franka_rest_planner, offset):
    """The default solver (Hessian assembled every third iteration, arm tolerance 1e-6) and the Hessian assembled
    at every iteration with tolerance 1e-8 end at the same cold and warm plans: J within 1e-6 relative (measured:
    about 1e-9, studies/which_newton_options_suit_the_arm/compare_solver_options.py) and mean hand paths within 1 mm."""
    from comanip.planning.solver_options import SolverOptions

    eager = comanip.Planner(franka_rest_planner.model, SolverOptions(hessian_refresh=1, arm_tolerance=None))
    body = eager.model.body
    start = np.r_[body.home_position, np.zeros(7)]
    goal = np.asarray(body.kinematics_function(body.home_position)[0]).ravel() + offset
    plans = {}
    for name, planner in (("lazy", franka_rest_planner), ("eager", eager)):
        cold = planner.solve(start, goal)
        plans[name] = (cold, planner.solve(start, goal + [0.04, -0.03, 0.03], warm_start=cold))
    for lazy, exact in zip(plans["lazy"], plans["eager"]):
        assert lazy.success and exact.success
        assert lazy.objective == pytest.approx(exact.objective, rel=1e-6)
        assert np.max(np.linalg.norm(lazy.ee_mean - exact.ee_mean, axis=1)) < 1e-3
