"""The secant-corrected Hessian (comanip.optim.hessian_models.SecantHessian): corrections that would need a large
shift are dropped, smaller shifts keep them."""

from types import SimpleNamespace

import numpy as np
import pytest

from comanip.optim.hessian_models import CORRECTED_SHIFT_LIMIT, SecantHessian


def _corrected(assembled: np.ndarray, negative_curvature: float) -> tuple[SecantHessian, np.ndarray]:
    """A SecantHessian of ``assembled`` (e_0 one of its eigenvectors) after one step s = e_0 along which the gradient
    changed by y = -negative_curvature e_0: the rank-one correction puts the curvature along e_0 at
    -negative_curvature. Returns the Hessian model and its solve after that step."""
    hessians = SecantHessian(lambda data: assembled, refresh=1)
    size = len(assembled)
    first = SimpleNamespace(x=np.zeros(size), g=np.zeros(size), data=None)
    assert not isinstance(hessians.factor(first, 0, False), str)
    step = np.eye(size)[0]
    second = SimpleNamespace(x=step, g=-negative_curvature * step, data=None)
    factored = hessians.factor(second, 0, False)
    assert not isinstance(factored, str)
    return hessians, factored[0]


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
    shift = hessians.updated.shift
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
    assert not isinstance(hessians(assembled).factor(point, 0, False), str)
    broken = assembled.copy()
    broken[entry] = broken[entry[::-1]] = value
    assert hessians(broken).factor(point, 0, False) == "Hessian not finite"


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
