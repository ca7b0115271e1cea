"""The active-set Newton method (comanip.optim.active_set_newton.newton_minimize and its staged newton_solve) on
the bounded Rosenbrock function, against scipy's L-BFGS-B."""

import numpy as np
import pytest
import scipy.optimize

from comanip.optim import Evaluation
from comanip.optim.active_set_newton import newton_minimize, newton_solve
from comanip.optim.hessian_models import prepare_hessian


def test_newton_matches_scipy_on_a_bounded_rosenbrock():
    """An independent check of the method: the bounded Rosenbrock minimiser found by L-BFGS-B."""
    def evaluate(x):
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

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
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

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
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

    with pytest.raises(ValueError, match="hessian_refresh") as error:
        newton_minimize(evaluate, scipy.optimize.rosen_hess, np.zeros(3), np.full(3, -1.0), np.full(3, 1.0),
                        tolerance=1e-8, max_iterations=10, secant=secant, hessian_refresh=refresh)
    assert word in str(error.value)


def test_newton_stops_at_the_deadline():
    calls = []

    def evaluate(x):
        calls.append(1)
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

    result = newton_minimize(evaluate, scipy.optimize.rosen_hess, np.full(4, -1.2), np.full(4, -np.inf), np.full(4, np.inf),
                             tolerance=1e-12, max_iterations=100, expired=lambda: len(calls) > 3)
    assert result.status == "max_wall_time" and np.isfinite(result.fun)


@pytest.mark.parametrize("secant", [False, True])
def test_a_solve_paused_and_resumed_takes_the_iterates_of_one_run(secant):
    """newton_solve's stages: advancing to 7 iterations, then to the end, ends on the point, objective and status of
    one run to the end (bounded Rosenbrock, exact Hessian or secant corrections: the method's memory survives the
    pause); the pause itself reports 'max_iterations' at iteration 7."""
    from comanip.optim import Status, newton_solve

    def evaluate(x):
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

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


@pytest.mark.parametrize("secant", [False, True])
def test_a_pause_without_the_gradient_at_its_point_is_completed_to_the_eager_pause(secant):
    """advance(k, gradient_at_end=False) on the bounded Rosenbrock with a value-only trial function: the same point and
    objective as advance(k), the gradient there never evaluated (the gradients counted; optimality NaN), and
    completed() then gives the eager pause's optimality; going on from it takes the iterates of one run."""
    from comanip.optim import Status, newton_solve

    gradients = []

    def evaluate(x):
        gradients.append(x.copy())
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

    def value(x):
        return Evaluation(float(scipy.optimize.rosen(x)), None, x)

    hessian = (lambda x: 0.5 * (scipy.optimize.rosen_hess(x) + np.diag(np.diag(scipy.optimize.rosen_hess(x))))) if secant \
        else scipy.optimize.rosen_hess
    arguments = (evaluate, hessian, np.full(6, -1.2), np.full(6, -2.0), np.r_[np.full(5, 2.0), 0.5])
    options = dict(tolerance=1e-10, secant=secant, value=value)
    whole = newton_solve(*arguments, **options).advance(500)
    for k in (1, 4, 9):
        eager = newton_solve(*arguments, **options).advance(k)
        lazy_solve = newton_solve(*arguments, **options)
        gradients.clear()
        lazy = lazy_solve.advance(k, gradient_at_end=False)
        assert lazy.status == Status.MAX_ITERATIONS and lazy.nit == k and np.isnan(lazy.optimality)
        np.testing.assert_array_equal(lazy.x, eager.x)
        assert lazy.fun == eager.fun
        assert not any(np.array_equal(x, lazy.x) for x in gradients)  # no gradient at the point it ends on
        done = lazy_solve.completed()
        assert done.optimality == eager.optimality and np.array_equal(done.x, eager.x) and done.status == eager.status
        resumed = lazy_solve.advance(500)
        np.testing.assert_array_equal(resumed.x, whole.x)
        assert resumed.status == whole.status and resumed.success
    # a wall budget that runs out on such a point ends the solve there; completed() still evaluates it
    eager = newton_solve(*arguments, **options).advance(3)
    budgeted = newton_solve(*arguments, **options)
    budgeted.advance(3, gradient_at_end=False)
    budgeted.expired = lambda: True
    stopped = budgeted.advance(500, gradient_at_end=False)
    assert stopped.status == Status.MAX_WALL_TIME and budgeted.finished and np.isnan(stopped.optimality)
    done = budgeted.completed()
    assert done.optimality == eager.optimality and done.status == Status.MAX_WALL_TIME and budgeted.completed() is done


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_start_where_f_or_its_gradient_is_not_finite_fails_with_a_result(bad):
    """A start where the objective or its gradient is not finite ends the solve at once with status 'failed' and
    the start as its best point, never an exception (a control loop reads the result)."""
    from comanip.optim import Status, newton_solve

    def evaluate(x):
        return Evaluation(bad if x[0] > 0 else float(x @ x), np.where(x > 0, bad, 2 * x), x)

    result = newton_solve(evaluate, lambda x: 2 * np.eye(3), np.ones(3), np.full(3, -2.0), np.full(3, 2.0),
                          tolerance=1e-10).advance(50)
    assert result.status == Status.FAILED and not result.success and result.nit == 0
    np.testing.assert_array_equal(result.x, np.ones(3))
    assert "not finite at the start" in result.message


@pytest.mark.parametrize("secant", [False, True])
def test_a_prepared_hessian_at_the_start_takes_the_iterates_of_a_solve_that_assembles_it(secant):
    """The prepared first Hessian made at x0 itself is the one the solve would assemble there: the same iterates and
    one assembly fewer."""
    def evaluate(x):
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

    def hessian(x):
        assemblies.append(x)
        return scipy.optimize.rosen_hess(x)

    lb, ub = np.full(6, -2.0), np.r_[np.full(5, 2.0), 0.5]
    x0 = np.full(6, -1.2)
    results = {}
    for name in ("assembled", "prepared"):
        assemblies = []
        prepared = prepare_hessian(scipy.optimize.rosen_hess(x0)) if name == "prepared" else None
        solve = newton_solve(evaluate, hessian, x0, lb, ub, tolerance=1e-8, secant=secant, prepared=prepared)
        results[name] = ([solve.advance(k).x.copy() for k in range(1, 6)], solve.advance(200), len(assemblies))
    (steps, result, assembled), (prepared_steps, prepared_result, prepared_assembled) = results["assembled"], results["prepared"]
    for ours, theirs in zip(prepared_steps, steps):
        np.testing.assert_array_equal(ours, theirs)
    assert result.success and prepared_result.status == result.status and prepared_result.nit == result.nit
    np.testing.assert_array_equal(prepared_result.x, result.x)
    assert prepared_assembled == assembled - 1


@pytest.mark.parametrize("secant", [False, True])
def test_a_hessian_prepared_elsewhere_reaches_the_minimiser_of_the_start_s_own_gradient(secant):
    """A first Hessian from a point far from x0, or x0's own scaled a thousandfold down (a step a thousand times too
    long, which the line search cuts back), changes the first step, not the minimiser: the gradient is x0's own."""
    def evaluate(x):
        return Evaluation(float(scipy.optimize.rosen(x)), scipy.optimize.rosen_der(x), x)

    lb, ub = np.full(6, -2.0), np.r_[np.full(5, 2.0), 0.5]
    x0 = np.full(6, -1.2)
    reference = newton_minimize(evaluate, scipy.optimize.rosen_hess, x0, lb, ub, tolerance=1e-8, max_iterations=200)
    for matrix in (scipy.optimize.rosen_hess(np.full(6, 0.3)), 1e-3 * scipy.optimize.rosen_hess(x0)):
        solve = newton_solve(evaluate, scipy.optimize.rosen_hess, x0, lb, ub, tolerance=1e-8, secant=secant,
                             prepared=prepare_hessian(matrix))
        first, result = solve.advance(1).x.copy(), solve.advance(300)
        assert result.success, result.message
        np.testing.assert_allclose(result.x, reference.x, atol=1e-6)
        assert not np.allclose(first, newton_solve(evaluate, scipy.optimize.rosen_hess, x0, lb, ub, tolerance=1e-8,
                                                   secant=secant).advance(1).x)
