"""The secant-corrected Hessian (comanip.optim.hessian_models.SecantHessian): corrections that would need a large
shift are dropped, smaller shifts keep them; the symmetric rank-one update and the Woodbury solve of an updated
factor."""

from types import SimpleNamespace

import numpy as np
import pytest

from comanip.optim import shifted_cholesky
from comanip.optim.hessian_models import CORRECTED_SHIFT_LIMIT, SecantHessian
from comanip.optim.newton_loop import Stop


def _corrected(assembled: np.ndarray, negative_curvature: float) -> tuple[SecantHessian, np.ndarray]:
    """A SecantHessian of ``assembled`` (e_0 one of its eigenvectors) after one step s = e_0 along which the gradient
    changed by y = -negative_curvature e_0: the rank-one correction puts the curvature along e_0 at
    -negative_curvature. Returns the Hessian model and its solve after that step."""
    hessians = SecantHessian(lambda data: assembled, refresh=1)
    size = len(assembled)
    first = SimpleNamespace(x=np.zeros(size), g=np.zeros(size), data=None)
    assert not isinstance(hessians.factor(first, 0, False), Stop)
    step = np.eye(size)[0]
    second = SimpleNamespace(x=step, g=-negative_curvature * step, data=None)
    factored = hessians.factor(second, 0, False)
    assert not isinstance(factored, Stop)
    return hessians, factored.solve


@pytest.fixture
def assembled(rng):
    size = 12
    root = rng.normal(size=(size, size))
    matrix = root @ root.T / size + np.eye(size)
    matrix[0, 1:] = matrix[1:, 0] = 0.0  # e_0 an eigenvector: the correction's effect is known exactly
    return matrix


def test_corrections_needing_a_large_shift_are_dropped(assembled, rng):
    """A correction that makes the curvature along e_0 fifty times the largest diagonal entry below zero would need
    a shift far beyond the limit: the step is the assembled Hessian's own, and the corrections are reset."""
    scale = np.abs(np.diag(assembled)).max()
    hessians, solve = _corrected(assembled, 50 * scale)
    b = rng.normal(size=len(assembled))
    np.testing.assert_allclose(solve(b), np.linalg.solve(assembled, b), rtol=1e-10)
    assert not hessians.correction.any()


def test_corrections_needing_a_small_shift_are_kept(assembled, rng):
    """A correction that leaves the curvature along e_0 slightly negative (a thousandth of the largest diagonal
    entry) is factored with a shift below the limit: the step is that of the corrected, shifted matrix."""
    scale = np.abs(np.diag(assembled)).max()
    hessians, solve = _corrected(assembled, 1e-3 * scale)
    corrected = assembled + hessians.correction
    assert hessians.correction[0, 0] == pytest.approx(-assembled[0, 0] - 1e-3 * scale)
    shift = hessians.updated.cholesky.shift
    assert 0 < shift < CORRECTED_SHIFT_LIMIT
    b = rng.normal(size=len(assembled))
    np.testing.assert_allclose(solve(b), np.linalg.solve(corrected + shift * scale * np.eye(len(b)), b), rtol=1e-10)


@pytest.mark.parametrize("entry, value", [((0, 3), np.nan), ((3, 0), np.nan), ((2, 2), np.nan), ((4, 4), np.inf),
                                          ((1, 5), np.inf), ((11, 11), np.inf)])
@pytest.mark.parametrize("model", ["exact", "secant"])
def test_a_hessian_with_a_nan_or_inf_is_refused(assembled, entry, value, model):
    """A NaN or inf anywhere in the (symmetric) matrix, on its diagonal last of all, gives no step, only the reason;
    the finite matrix gives one."""
    from comanip.optim.hessian_models import ExactHessian

    def hessians(matrix):
        return ExactHessian(lambda data: matrix) if model == "exact" else SecantHessian(lambda data: matrix, refresh=1)

    point = SimpleNamespace(x=np.zeros(len(assembled)), g=np.zeros(len(assembled)), data=None)
    assert not isinstance(hessians(assembled).factor(point, 0, False), Stop)
    broken = assembled.copy()
    broken[entry] = broken[entry[::-1]] = value
    assert hessians(broken).factor(point, 0, False).message == "Hessian not finite"


@pytest.mark.parametrize("gradient, finite", [([0.0, -2.0], True), ([0.0, np.nan], False), ([np.inf, 1.0], False),
                                              (None, True)])
def test_an_iterate_is_finite_when_f_and_its_gradient_are(gradient, finite):
    from comanip.optim.active_set import NO_MULTIPLIERS, Iterate

    g = None if gradient is None else np.array(gradient)
    point = Iterate(np.zeros(2), 1.0, g, None, NO_MULTIPLIERS, None)
    assert point.finite is finite
    assert Iterate(np.zeros(2), np.nan, g, None, NO_MULTIPLIERS, None).finite is False
    if finite and g is not None:
        assert point.steepest == 2.0


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


def test_updated_factor_solves_with_the_updated_matrix_and_refuses_an_indefinite_one(rng):
    """The Woodbury solve after secant updates equals a direct solve with F + Σ sign_j u_j u_jᵀ, and an update
    that makes the matrix indefinite (eigenvalues checked directly) gives None."""
    from comanip.optim.hessian_models import RankOneUpdate, UpdatedFactor

    size = 30
    root = rng.normal(size=(size, size))
    F = root @ root.T + size * np.eye(size)
    factor = UpdatedFactor(shifted_cholesky(F, (0.0,)))
    matrix = F.copy()
    for sign in (1.0, -1.0):
        u = rng.normal(size=size)
        factor = factor.updated(RankOneUpdate(u, sign))
        matrix += sign * np.outer(u, u)
        assert np.linalg.eigvalsh(matrix)[0] > 0 and factor is not None
        b = rng.normal(size=(size, 3))
        np.testing.assert_allclose(factor.solve(b), np.linalg.solve(matrix, b), rtol=1e-9, atol=1e-12)
    eigenvalues, vectors = np.linalg.eigh(matrix)
    breaking = vectors[:, 0] * np.sqrt(2 * eigenvalues[0])  # subtracting it leaves eigenvalue -eigenvalues[0]
    assert np.linalg.eigvalsh(matrix - np.outer(breaking, breaking))[0] < 0
    assert factor.updated(RankOneUpdate(breaking, -1.0)) is None
    assert factor.updated(None) is factor
