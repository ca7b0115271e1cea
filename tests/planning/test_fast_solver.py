"""The fast solver layer: structured Hessian, compiled functions and their cache, the Newton method, and
its optimum against IPOPT with CasADi's exact Hessian (the reference)."""

import pickle
import warnings

import casadi as ca
import numpy as np
import pytest
import scipy.optimize

import comanip
from comanip.caching import compiled as compiled_module
from comanip.caching.buffered_function import BufferedFunction
from comanip.caching.compiled import compile_in_background, compiled
from comanip.planning.curvature import ReachCurvature
from comanip.optim.active_set_newton import newton_minimize
from comanip.planning.planner import Planner, SolverOptions
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
        value, gradient, data = curvature.evaluate(tau, p)
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


def test_newton_matches_scipy_on_a_bounded_rosenbrock():
    """An independent check of the method: the bounded Rosenbrock minimiser found by L-BFGS-B."""
    def evaluate(x):
        return float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x

    lb, ub = np.full(6, -2.0), np.r_[np.full(5, 2.0), 0.5]
    result = newton_minimize(evaluate, scipy.optimize.rosen_hess, np.full(6, -1.2), lb, ub, tolerance=1e-8, max_iterations=200)
    reference = scipy.optimize.minimize(scipy.optimize.rosen, np.full(6, -1.2), jac=scipy.optimize.rosen_der,
                                        method="L-BFGS-B", bounds=list(zip(lb, ub)), options={"ftol": 1e-15, "gtol": 1e-12})
    assert result.status == "solved"
    assert result.x[-1] == pytest.approx(0.5)  # the bound is active
    np.testing.assert_allclose(result.x, reference.x, atol=1e-6)
    assert result.fun <= reference.fun + 1e-12


def test_hessian_refresh_reaches_the_same_minimiser_with_fewer_assemblies():
    """An approximate Hessian (the Rosenbrock function's with its off-diagonal halved) assembled every third
    iteration, secant corrections in between, reaches the minimiser of every-iteration assembly, and of L-BFGS-B
    with a bound active; without bounds it assembles at most one Hessian per two iterations (a short step or a
    constraint in the working set brings an assembly back sooner)."""
    def evaluate(x):
        return float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x

    def approximate_hessian(x):
        assemblies.append(x)
        exact = scipy.optimize.rosen_hess(x)
        return 0.5 * (exact + np.diag(np.diag(exact)))

    free = (np.full(6, -np.inf), np.full(6, np.inf))
    bounded = (np.full(6, -2.0), np.r_[np.full(5, 2.0), 0.5])
    for lb, ub in (free, bounded):
        results = {}
        for refresh in (1, 3):
            assemblies = []
            result = newton_minimize(evaluate, approximate_hessian, np.full(6, -1.2), lb, ub, tolerance=1e-8,
                                     max_iterations=500, secant=True, hessian_refresh=refresh)
            assert result.success, result.message
            results[refresh] = (result, len(assemblies))
        lazy, eager = results[3][0], results[1][0]
        np.testing.assert_allclose(lazy.x, eager.x, atol=1e-6)
        assert lazy.fun == pytest.approx(eager.fun, rel=1e-9, abs=1e-15)
        assert results[3][1] <= (lazy.nit / 2 if lb is free[0] else lazy.nit - 1)
    reference = scipy.optimize.minimize(scipy.optimize.rosen, np.full(6, -1.2), jac=scipy.optimize.rosen_der,
                                        method="L-BFGS-B", bounds=list(zip(*bounded)), options={"ftol": 1e-15, "gtol": 1e-12})
    np.testing.assert_allclose(lazy.x, reference.x, atol=1e-6)


@pytest.mark.parametrize("refresh, secant, word", [(0, True, "≥ 1"), (1.5, True, "≥ 1"), (True, True, "≥ 1"),
                                                   (2, False, "without secant")])
def test_hessian_refresh_is_checked(refresh, secant, word):
    def evaluate(x):
        return float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x

    with pytest.raises(ValueError, match="hessian_refresh") as error:
        newton_minimize(evaluate, scipy.optimize.rosen_hess, np.zeros(3), np.full(3, -1.0), np.full(3, 1.0),
                        tolerance=1e-8, max_iterations=10, secant=secant, hessian_refresh=refresh)
    assert word in str(error.value)


def test_symmetric_rank_one_update_meets_the_secant_equation(rng):
    """After the update in place, (H + C) s = y, C stays symmetric and C's change is rank one; a residual r
    orthogonal to s (no finite update meets the equation) leaves C alone."""
    from comanip.optim.hessian_models import symmetric_rank_one_update

    size = 40
    H, C = (lambda M: M + M.T)(rng.normal(size=(size, size))), (lambda M: M + M.T)(rng.normal(size=(size, size)))
    s, y = rng.normal(size=size), rng.normal(size=size)
    before = C.copy()
    symmetric_rank_one_update(C, H, s, y)
    np.testing.assert_allclose((H + C) @ s, y, atol=1e-10 * np.abs(y).max())
    np.testing.assert_array_equal(C, C.T)
    assert np.linalg.matrix_rank(C - before, tol=1e-8 * np.abs(C - before).max()) == 1
    unchanged = C.copy()
    w = rng.normal(size=size)
    symmetric_rank_one_update(C, H, s, (H + C) @ s + w - (w @ s) / (s @ s) * s)  # r ⟂ s: no finite update
    np.testing.assert_array_equal(C, unchanged)


def test_a_step_never_drives_a_row_past_its_limit_further_out():
    """Two rows past their limits within the tolerance, both with negative multipliers: dropping both at once
    gives the step -g, which moves row 0 further out (a first-order rise of the merit's penalty: no step length
    is accepted, the Panda's 'failed' stalls along a joint limit). Row 0 must stay in the working set and the step
    still descend."""
    from comanip.optim.active_set import constrained_step

    rows = np.array([[1.0, 0.0], [-1.0, 1.0]])
    g = np.array([-0.9, 1.0])  # multipliers with both rows working: (-0.1, -1.0)
    c = np.array([5e-7, 5e-7])
    step, multipliers, working, _ = constrained_step(lambda b: b, g, c, lambda indices: rows[indices],
                                                      margin=1e-3, tolerance=1e-6)
    assert np.all(rows @ step <= 1e-12), rows @ step
    assert g @ step < 0
    assert working.tolist() == [0] and multipliers[0] > 0
    np.testing.assert_allclose(step, [-c[0], -1.0], atol=1e-12)  # row 0 brought back onto its limit


def test_updated_factor_solves_with_the_updated_matrix_and_refuses_an_indefinite_one(rng):
    """The Woodbury solve after secant updates equals a direct solve with F + Σ sign_j u_j u_jᵀ, and an update
    that makes the matrix indefinite (eigenvalues checked directly) gives None."""
    from comanip.optim.hessian_models import UpdatedFactor

    size = 30
    root = rng.normal(size=(size, size))
    F = root @ root.T + size * np.eye(size)
    factor = UpdatedFactor(scipy.linalg.cho_factor(F), 0.0)
    matrix = F.copy()
    for sign in (1.0, -1.0):
        u = rng.normal(size=size)
        factor = factor.updated((u, sign))
        matrix += sign * np.outer(u, u)
        assert np.linalg.eigvalsh(matrix)[0] > 0 and factor is not None
        b = rng.normal(size=(size, 3))
        np.testing.assert_allclose(factor.solve(b), np.linalg.solve(matrix, b), rtol=1e-9, atol=1e-12)
    eigenvalues, vectors = np.linalg.eigh(matrix)
    breaking = vectors[:, 0] * np.sqrt(2 * eigenvalues[0])  # subtracting it leaves eigenvalue -eigenvalues[0]
    assert np.linalg.eigvalsh(matrix - np.outer(breaking, breaking))[0] < 0
    assert factor.updated((breaking, -1.0)) is None
    assert factor.updated(None) is factor


def test_newton_stops_at_the_deadline():
    calls = []

    def evaluate(x):
        calls.append(1)
        return float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x

    result = newton_minimize(evaluate, scipy.optimize.rosen_hess, np.full(4, -1.2), np.full(4, -np.inf), np.full(4, np.inf),
                             tolerance=1e-12, max_iterations=100, expired=lambda: len(calls) > 3)
    assert result.status == "max_wall_time" and np.isfinite(result.fun)


def test_compiled_cache_keys_on_the_function_and_falls_back_without_a_compiler(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 3)
    for kappa in (1.0, 2.0):
        f = ca.Function("cached_test", [x], [kappa * ca.sin(x) * ca.sumsqr(x)])
        fast = compiled(f)
        point = np.array([0.3, -1.0, 2.0])
        np.testing.assert_allclose(np.asarray(fast(point)).ravel(), np.asarray(f(point)).ravel(), rtol=1e-14)
    libraries = sorted(tmp_path.glob("cached_test_*.so"))
    assert len(libraries) == 2  # a changed constant is a changed function: a new library
    stamp = libraries[0].stat().st_mtime_ns
    compiled(ca.Function("cached_test", [x], [1.0 * ca.sin(x) * ca.sumsqr(x)]))
    assert libraries[0].stat().st_mtime_ns == stamp and len(list(tmp_path.glob("*.so"))) == 2  # reused, not rebuilt
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    g = ca.Function("uncompiled_test", [x], [ca.cos(x)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fallback = compiled(g)
    assert any("could not compile" in str(w.message) for w in caught)
    np.testing.assert_allclose(BufferedFunction(fallback)(np.ones(3))[0].ravel(), np.cos(np.ones(3)))


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


@pytest.mark.parametrize("secant", [False, True])
def test_a_solve_paused_and_resumed_takes_the_iterates_of_one_run(secant):
    """newton_solve's stages: advancing to 7 iterations, then to the end, ends on the point, objective and status of
    one run to the end (bounded Rosenbrock, exact Hessian or secant corrections: the method's memory survives the
    pause); the pause itself reports 'max_iterations' at iteration 7."""
    from comanip.optim import Status, newton_solve

    def evaluate(x):
        return float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x

    hessian = (lambda x: 0.5 * (scipy.optimize.rosen_hess(x) + np.diag(np.diag(scipy.optimize.rosen_hess(x))))) if secant \
        else scipy.optimize.rosen_hess
    arguments = (evaluate, hessian, np.full(6, -1.2), np.full(6, -2.0), np.r_[np.full(5, 2.0), 0.5])
    options = dict(tolerance=1e-10, secant=secant, hessian_refresh=3 if secant else 1)
    whole = newton_solve(*arguments, **options).advance(500)
    staged = newton_solve(*arguments, **options)
    paused = staged.advance(7)
    assert paused.status == Status.MAX_ITERATIONS and paused.nit == 7 and not staged.finished
    resumed = staged.advance(500)
    assert staged.finished and resumed.status == whole.status and resumed.success
    np.testing.assert_array_equal(resumed.x, whole.x)
    assert resumed.fun == whole.fun and abs(resumed.nit - whole.nit) <= 1
    assert staged.advance(1000) is resumed  # a finished solve only reports


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


def test_shifted_cholesky_solves_the_shifted_system(rng):
    """The factor of an indefinite matrix comes with the shift that made it definite, and solves that system."""
    from comanip.optim import cholesky_solve, growing_shifts, shifted_cholesky

    A = rng.normal(size=(30, 30))
    matrix = A + A.T  # indefinite
    factor, delta = shifted_cholesky(matrix, growing_shifts(0.0))
    assert delta > 0
    shifted = matrix + delta * np.max(np.abs(np.diag(matrix))) * np.eye(30)
    assert np.linalg.eigvalsh(shifted).min() > 0
    b = rng.normal(size=(30, 2))
    np.testing.assert_allclose(cholesky_solve(factor, b), np.linalg.solve(shifted, b), rtol=1e-9, atol=1e-12)
    definite = A @ A.T + np.eye(30)
    factor, delta = shifted_cholesky(definite, growing_shifts(0.0))
    assert delta == 0.0
    np.testing.assert_allclose(cholesky_solve(factor, b[:, 0]), np.linalg.solve(definite, b[:, 0]), rtol=1e-9)
    assert shifted_cholesky(-np.eye(3), (0.0,))[0] is None  # no shift allowed: no factor


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


def test_a_tagged_build_is_found_without_generating_source_and_only_for_the_same_libraries(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 2)
    f = ca.Function("tagged_test", [x], [ca.sin(x) * x[1]])
    first = compiled_module.compiled_or_cached(f, "model A")
    monkeypatch.setattr(ca, "CodeGenerator", None)  # generating source now fails
    again = compiled_module.compiled_or_cached(f, "model A")
    point = np.array([0.2, 3.0])
    np.testing.assert_array_equal(np.asarray(again(point)), np.asarray(first(point)))
    assert compiled_module.cached_compiled("tagged_test", "model B") is None
    version = compiled_module.metadata.version
    monkeypatch.setattr(compiled_module.metadata, "version", lambda name: "0.0" if name == "adam-robotics" else version(name))
    compiled_module._source_fingerprint.cache_clear()
    try:
        assert compiled_module.cached_compiled("tagged_test", "model A") is None  # another adam: another dynamics
    finally:
        monkeypatch.undo()
        compiled_module._source_fingerprint.cache_clear()


def test_background_compile_skips_a_collected_owner_and_builds_for_a_live_one(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 2)

    class Owner:
        function = ca.Function("background_test", [x], [ca.exp(x) * x[0]])

    kept, dropped = Owner(), Owner()
    with compiled_module.COMPILERS.turn:  # as if another build were running: both wait their turn
        gone = compile_in_background(dropped, lambda owner: [owner.function])
        built = compile_in_background(kept, lambda owner: [owner.function])
        del dropped  # collected before its turn
    assert gone.result(timeout=120) is None
    point = np.array([0.5, -2.0])
    np.testing.assert_array_equal(np.asarray(built.result(timeout=120)[0](point)), np.asarray(Owner.function(point)))
    assert len(list(tmp_path.glob("background_test_*.so"))) == 1


def test_a_compiler_running_at_exit_is_stopped_and_its_scratch_removed(tmp_path):
    import subprocess

    scratch = tmp_path / "scratch"
    scratch.mkdir()
    process = subprocess.Popen(["sleep", "60"])
    compiled_module.COMPILERS.running[process] = str(scratch)
    try:
        compiled_module.COMPILERS.stop_running()
    finally:
        compiled_module.COMPILERS.running.pop(process, None)
    assert process.poll() is not None and not scratch.exists()


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
                                          (dict(compile_after=-1.0), "compile_after"),
                                          (dict(arm_tolerance=-1e-6), "arm_tolerance"), (dict(hessian_refresh=0), "hessian_refresh"),
                                          (dict(threads=0), "threads")])
def test_bad_solver_options_name_the_field(kwargs, word):
    with pytest.raises(ValueError, match=word):
        SolverOptions(**kwargs)


def test_the_compile_cache_survives_an_edit_outside_the_formulation(tmp_path):
    """The fingerprint that keys compiled functions (the Panda's take minutes to build) changes with the code
    they are built from, not with a plot module or a command."""
    import shutil
    package = tmp_path / "comanip"
    shutil.copytree(compiled_module.PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__", "*.pkl", "*.npz"))
    before = compiled_module._source_fingerprint(package)
    for outside in ("plots/__init__.py", "cli/main.py", "simulation/sync_scenario.py"):
        (package / outside).write_text((package / outside).read_text() + "\n# an edit\n")
        assert compiled_module._source_fingerprint.__wrapped__(package) == before, outside
    (package / "objectives" / "reward.py").write_text((package / "objectives" / "reward.py").read_text() + "\n# an edit\n")
    assert compiled_module._source_fingerprint.__wrapped__(package) != before
