"""The working set's constrained step (comanip.optim.active_set)."""

import numpy as np
import pytest


def test_a_step_never_drives_a_row_past_its_limit_further_out():
    """Two rows past their limits within the tolerance, both with negative multipliers: dropping both at once
    gives the step -g, which moves row 0 further out (a first-order rise of the merit's penalty: no step length
    is accepted, the Panda's 'failed' stalls along a joint limit). Row 0 must stay in the working set and the step
    still descend."""
    from comanip.optim.active_set import constrained_step

    rows = np.array([[1.0, 0.0], [-1.0, 1.0]])
    g = np.array([-0.9, 1.0])  # multipliers with both rows working: (-0.1, -1.0)
    c = np.array([5e-7, 5e-7])
    step, multipliers, working, _, _ = constrained_step(lambda b: b, g, c, lambda indices: rows[indices],
                                                      margin=1e-3, tolerance=1e-6)
    assert np.all(rows @ step <= 1e-12), rows @ step
    assert g @ step < 0
    assert working.tolist() == [0] and multipliers[0] > 0
    np.testing.assert_allclose(step, [-c[0], -1.0], atol=1e-12)  # row 0 brought back onto its limit


def test_the_step_solves_the_quadratic_model_on_the_working_rows_it_returns():
    """On random positive definite models with independent constraint rows near their limits (some dropped for a negative
    multiplier, some pinned back), the step and multipliers satisfy the KKT conditions of the quadratic model with the
    returned working rows as equalities, H d + g + A_Wᵀ λ = 0 and A_W d = -c_W, with λ ≥ 0, checked by a solve of
    its own; the second-order correction moves onto the working rows' linearisation."""
    from comanip.optim.active_set import constrained_step

    rng = np.random.default_rng(4)
    dropped_some = 0
    for _ in range(200):
        n = int(rng.integers(3, 12))
        m = int(rng.integers(1, n))  # independent rows: fewer than the unknowns
        root = rng.normal(size=(n, n))
        hessian = root @ root.T + 0.1 * np.eye(n)
        g, rows = rng.normal(size=n), rng.normal(size=(m, n))
        c = rng.choice([0.0, 5e-7, -1e-4, -1.0], size=m)  # on, just past, near and far from the limit
        step, multipliers, working, correct, optimality = constrained_step(lambda b: np.linalg.solve(hessian, b), g, c,
                                                               lambda indices: rows[indices], margin=1e-3,
                                                               tolerance=1e-6)
        near = np.flatnonzero(c > -1e-3)
        assert set(working.tolist()) <= set(near.tolist()) and np.all(np.diff(working) > 0)
        dropped_some += len(working) < len(near)
        stationarity = hessian @ step + g + rows[working].T @ multipliers
        np.testing.assert_allclose(stationarity, 0.0, atol=1e-8 * (1 + np.abs(g).max()))
        assert optimality == pytest.approx(np.abs(g + rows[working].T @ multipliers).max(), rel=1e-12, abs=1e-15)
        if len(working):
            np.testing.assert_allclose(rows[working] @ step, -c[working], atol=1e-9)
            assert np.all(multipliers >= 0)
            shift = rng.normal(size=len(working))
            np.testing.assert_allclose(rows[working] @ correct(shift), -shift, atol=1e-9)
        else:
            assert correct is None
    assert dropped_some > 20  # the cases exercise the dropping


def test_rows_that_depend_on_one_another_get_the_least_norm_multipliers():
    """A working row given twice (a limit met by two rows of the Jacobian at once): the Schur complement is singular,
    and the multipliers are the least-norm ones, split evenly; the step is that of the row given once."""
    from comanip.optim.active_set import constrained_step

    hessian = np.diag([2.0, 1.0, 4.0])
    g, row = np.array([1.0, -2.0, 0.5]), np.array([[1.0, 1.0, 0.0]])
    solve = lambda b: np.linalg.solve(hessian, b)  # noqa: E731
    once = constrained_step(solve, g, np.zeros(1), lambda indices: row[np.zeros(len(indices), dtype=int)], 1e-3, 1e-6)
    twice = constrained_step(solve, g, np.zeros(2), lambda indices: row[np.zeros(len(indices), dtype=int)], 1e-3, 1e-6)
    assert once[2].tolist() == [0] and twice[2].tolist() == [0, 1]
    np.testing.assert_allclose(twice[0], once[0], atol=1e-12)
    np.testing.assert_allclose(twice[1], [once[1][0] / 2] * 2, atol=1e-12)
    assert np.all(np.isfinite(twice[3](np.array([1e-3, 1e-3]))))
