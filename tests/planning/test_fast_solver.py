"""The planner's fast solves: the structured Hessian, the Newton optimum against IPOPT with CasADi's exact Hessian
(the reference), the goal sensitivity a plan carries, chord steps and the background compile of a point mass's
terms."""

import pickle

import casadi as ca
import numpy as np
import pytest

import comanip
from comanip.planning.curvature import ReachCurvature
from comanip.planning.planner import Planner
from comanip.planning.solver_options import SolverOptions
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_parameters import ReachParameters


@pytest.fixture(scope="module")
def planar_reference():
    return Planner(comanip.presets.planar(), SolverOptions(method="ipopt"))


@pytest.mark.parametrize("preset, noise", [("planar", "isotropic"), ("planar", "per_channel"), ("planar", "rank_one"),
                                           ("cartesian", "isotropic")])
def test_structured_hessian_equals_casadi_exact_hessian(preset, noise, rng):
    """The per-step assembly against CasADi's forward-over-reverse Hessian of the whole rollout."""
    model = comanip.presets.load(preset).replace(noise=noise, H=12)
    problem = ReachProblem(model)
    curvature = ReachCurvature(problem)
    x = ca.vec(problem.tau)
    f = problem.objective / -problem.best_objective
    exact = ca.Function("exact", [x, problem.s0, problem.goal, problem.width], [ca.hessian(f, x)[0], ca.gradient(f, x), f])
    for _ in range(3):
        tau = rng.normal(scale=3.0, size=x.numel())
        p = ReachParameters(rng.normal(scale=0.1, size=2 * model.n), rng.uniform(0.1, 0.3, model.d), rng.uniform(0.01, 0.05))
        evaluation = curvature.evaluate(tau, p)
        value, gradient, data = evaluation.f, evaluation.gradient, evaluation.data
        H_exact, g_exact, f_exact = (np.asarray(v) for v in exact(tau, p.start, p.goal, p.width))
        assert value == pytest.approx(f_exact.item(), rel=1e-12)
        np.testing.assert_allclose(gradient, g_exact.ravel(), rtol=1e-10, atol=1e-12 * np.abs(g_exact).max())
        np.testing.assert_allclose(curvature.hessian(data), H_exact, rtol=1e-9, atol=1e-11 * np.abs(H_exact).max())


def test_newton_optimum_equals_ipopt_exact_hessian_optimum(planar_planner, planar_reference, rng):
    """Same start, same problem: the fast solver and the reference converge to the same plan."""
    model = planar_planner.model
    for start, goal, width in [(np.zeros(4), [0.3, 0.0], 0.02), (np.zeros(4), [0.45, 0.1], 0.005),
                               (np.r_[0.05, -0.05, 0.3, 0.1], [0.2, 0.15], 0.04)]:
        fast = planar_planner.solve(start, goal, width)
        reference = planar_reference.solve(start, goal, width, warm_start=fast.torque + rng.normal(scale=0.3, size=(model.H, 2)))
        again = planar_planner.solve(start, goal, width, warm_start=reference)
        assert fast.success and reference.success and again.success
        assert again.objective == pytest.approx(reference.objective, rel=1e-8)
        np.testing.assert_allclose(again.torque, reference.torque, atol=1e-4 * np.abs(reference.torque).max())
        assert fast.objective <= reference.objective + 1e-8 * abs(reference.objective)


def test_cartesian_warm_solves_match_the_reference(cartesian_planner):
    """Warm solves to nearby goals (the benchmark's pattern) reach the reference's optimum from the same start."""
    reference = Planner(comanip.presets.cartesian(), SolverOptions(method="ipopt"))
    start = np.zeros(6)
    previous = cartesian_planner.solve(start, [0.3, 0.0, 0.0])
    for goal in ([0.33, 0.04, -0.02], [0.28, -0.03, 0.05]):
        fast = cartesian_planner.solve(start, goal, warm_start=previous)
        ref = reference.solve(start, goal, warm_start=previous)
        assert fast.success and ref.success
        assert fast.objective == pytest.approx(ref.objective, rel=1e-7)
        previous = fast


def test_goal_sensitivity_of_a_plan_matches_finite_differences_of_solved_plans():
    """d tau*/d goal that a point-mass plan carries (implicit function theorem with its solve's last
    factorisation) against central differences of plans solved to goals 0.1 mm away; a wrong sign or a
    missing term is off by the whole column."""
    model = comanip.presets.planar()
    planner = Planner(model, SolverOptions(tolerance=1e-11))
    start, goal, width = np.zeros(4), np.array([0.25, 0.04]), 0.02
    plan = planner.solve(start, goal, width)
    sensitivity = plan.goal_sensitivity.matrix()
    assert sensitivity.shape == (model.H * model.n, model.d)
    step = 1e-4
    for k in range(model.d):
        shift = step * np.eye(model.d)[k]
        ahead, behind = (Planner(model, SolverOptions(tolerance=1e-11)).solve(start, goal + sign * shift, width, warm_start=plan.torque)
                         for sign in (1, -1))
        difference = (ahead.torque - behind.torque).ravel() / (2 * step)
        # to 2 %: the factorisation is the Hessian's of the last step, one or two iterates before the optimum
        np.testing.assert_allclose(sensitivity[:, k], difference, rtol=0, atol=2e-2 * np.abs(difference).max())


def test_the_goal_predictor_applies_only_to_the_planners_own_plans_at_their_start_and_width():
    """A plan carries its goal sensitivity: a warm start from it is predicted by the planner that solved it
    (whatever it solved since: a solve depends only on its arguments), from the same start and width; not by
    another planner, and not once the plan has been sent to another process (pickled)."""
    model = comanip.presets.planar()
    planner, other = Planner(model), Planner(model)
    start, goal, width = np.zeros(4), np.array([0.3, 0.0]), 0.02
    plan = planner.solve(start, goal, width)
    moved = goal + np.array([0.02, -0.01])
    predicted = planner.starts.predicted(plan, ReachParameters(start, moved, width))
    np.testing.assert_allclose(predicted, plan.torque + (plan.goal_sensitivity.matrix() @ (moved - goal)).reshape(plan.torque.shape))
    assert planner.starts.predicted(other.solve(start, goal, width), ReachParameters(start, moved, width)) is None  # another planner's plan
    assert planner.starts.predicted(plan, ReachParameters(start, moved, 0.01)) is None  # another width
    assert planner.starts.predicted(plan, ReachParameters(np.array([0.0, 0.0, 0.1, 0.0]), moved, width)) is None  # another start
    planner.solve(start, moved, width)
    np.testing.assert_allclose(planner.starts.predicted(plan, ReachParameters(start, moved, width)), predicted)  # not only the last plan
    assert pickle.loads(pickle.dumps(plan)).goal_sensitivity is None
    assert "goal_sensitivity" not in plan.to_dict()


def test_final_position_change_is_the_change_of_the_rolled_out_end(rng):
    """For a point mass the mean is affine in the torques: the end's change the curvature predicts from its constant
    sensitivities equals the difference of two expanded rollouts (an independent construction)."""
    model = comanip.presets.cartesian()
    planner = Planner(model)
    start, goal = np.r_[np.zeros(3), rng.normal(scale=0.2, size=3)], np.array([0.3, 0.1, 0.0])
    torque, change = rng.normal(scale=2.0, size=(model.H, 3)), rng.normal(scale=0.5, size=(model.H, 3))
    end = lambda tau: np.asarray(planner.problem.trajectory(tau=np.ravel(tau), s0=start, goal=goal, width=model.width)["ee_mean"])[:, -1]  # noqa: E731
    np.testing.assert_allclose(planner.curvature.final_position_change(change), end(torque + change) - end(torque), atol=1e-12)


def test_fresh_reaches_compete_with_a_warm_start_only_where_its_prediction_ends_far_from_the_goal(monkeypatch):
    """A plan to a goal 10 widths away ends far from the new goal, but its goal predictor moves it onto the new goal:
    no fresh reach competes. A plan without its sensitivity (torques only, or another planner's) ends as far as it
    was planned, and the minimum-jerk reaches compete."""
    model = comanip.presets.planar()
    planner = Planner(model)
    start, goal, width = np.zeros(4), np.array([0.25, 0.0]), 0.02
    plan = planner.solve(start, goal, width)
    moved = goal + np.array([0.0, 10 * width])
    fresh = []
    cold_guesses = planner.starts.cold_guesses
    monkeypatch.setattr(planner.starts, "cold_guesses", lambda *args: fresh.append(1) or cold_guesses(*args))
    predicted = planner.solve(start, moved, width, warm_start=plan)
    assert predicted.success and not fresh
    from_torques = planner.solve(start, moved, width, warm_start=Planner(model).solve(start, goal, width))
    assert from_torques.success and len(fresh) == 1
    assert predicted.objective == pytest.approx(from_torques.objective, rel=1e-9)


def test_chord_steps_reach_the_same_optimum_with_fewer_hessians(monkeypatch):
    """Warm point-mass solves reusing a factorisation (comanip.optim.hessian_models.ExactHessian, chord steps) against fresh Hessians at
    every iteration: the same plans (J to 1e-9 relative), fewer Hessians in all."""
    import comanip.optim.hessian_models as newton

    model = comanip.presets.cartesian()
    planner = Planner(model)
    hessians = []
    exact = planner.curvature.hessian
    monkeypatch.setattr(planner.curvature, "hessian", lambda data: hessians.append(1) or exact(data))
    start, goal = np.zeros(6), np.array([0.3, 0.0, 0.0])
    plan = planner.solve(start, goal, model.width)
    rng = np.random.default_rng(3)
    counts, objectives = {}, {}
    for ratio in (newton.REUSE_RATIO, 0.0):
        monkeypatch.setattr(newton, "REUSE_RATIO", ratio)
        hessians.clear()
        plans = [planner.solve(start, goal + rng.uniform(-0.05, 0.05, 3), model.width, warm_start=plan) for _ in range(8)]
        assert all(p.success for p in plans)
        counts[ratio], objectives[ratio] = len(hessians), np.array([p.objective for p in plans])
        rng = np.random.default_rng(3)
    chord, fresh = counts
    np.testing.assert_allclose(objectives[chord], objectives[fresh], rtol=1e-9)
    assert counts[chord] < counts[fresh]


def test_a_point_mass_planner_compiles_in_the_background_after_its_solving_time(tmp_path, monkeypatch):
    """Past ``compile_after`` seconds of solving the planner's terms switch to C, with the same plans."""
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    model = comanip.presets.planar().replace(H=12)
    planner = Planner(model, SolverOptions(compile_after=1e-6))
    never = Planner(model, SolverOptions(compile=False))
    start, goal = np.zeros(4), np.array([0.25, 0.05])
    first = planner.solve(start, goal, 0.02)
    curvature = planner.curvature
    assert curvature._compiling is not None  # started by the first solve
    curvature._compiling.result(timeout=120)
    again = planner.solve(start, goal, 0.02)
    assert curvature._compiling is None
    assert {curvature._terms.function.class_name(), curvature._value.function.class_name()} == {"External"}
    reference = never.solve(start, goal, 0.02)
    np.testing.assert_allclose(again.torque, reference.torque, rtol=0, atol=1e-12)
    np.testing.assert_allclose(first.torque, reference.torque, rtol=0, atol=1e-12)
    assert never.curvature._compiling is None  # compile=False never compiles
    # a later planner for the same model loads the build from the cache at once; another model does not
    kinds = {options: [Planner(changed, SolverOptions(compile=options)).curvature._terms.function.class_name()
                       for changed in (model, model.replace(nu=2 * model.nu))] for options in (None, False)}
    assert kinds == {None: ["External", "SXFunction"], False: ["SXFunction", "SXFunction"]}
    assert Planner(model).curvature._value.function.class_name() == "External"


@pytest.mark.parametrize("kwargs, word", [(dict(method="lbfgs"), "method"), (dict(tolerance=0.0), "tolerance"),
                                          (dict(max_iterations=0), "max_iterations"), (dict(n_starts=1.5), "n_starts"),
                                          (dict(cold_search="best"), "cold_search"), (dict(narrow_ratio=0.0), "narrow_ratio"),
                                          (dict(arm_narrow_ratio=-4.0), "arm_narrow_ratio"),
                                          (dict(compile_after=-1.0), "compile_after"),
                                          (dict(arm_tolerance=-1e-6), "arm_tolerance"), (dict(hessian_refresh=0), "hessian_refresh"),
                                          (dict(threads=0), "threads")])
def test_bad_solver_options_name_the_field(kwargs, word):
    with pytest.raises(ValueError, match=word):
        SolverOptions(**kwargs)
