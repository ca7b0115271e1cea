"""The shifted Cholesky factorisation (comanip.optim.factorisation)."""

import numpy as np


def test_shifted_cholesky_solves_the_shifted_system(rng):
    """The factor of an indefinite matrix comes with the shift that made it definite, and solves that system."""
    from comanip.optim import growing_shifts, shifted_cholesky

    A = rng.normal(size=(30, 30))
    matrix = A + A.T  # indefinite
    factor = shifted_cholesky(matrix, growing_shifts(0.0))
    delta = factor.shift
    assert delta > 0
    shifted = matrix + delta * np.max(np.abs(np.diag(matrix))) * np.eye(30)
    assert np.linalg.eigvalsh(shifted).min() > 0
    b = rng.normal(size=(30, 2))
    np.testing.assert_allclose(factor.solve(b), np.linalg.solve(shifted, b), rtol=1e-9, atol=1e-12)
    definite = A @ A.T + np.eye(30)
    factor = shifted_cholesky(definite, growing_shifts(0.0))
    assert factor.shift == 0.0
    np.testing.assert_allclose(factor.solve(b[:, 0]), np.linalg.solve(definite, b[:, 0]), rtol=1e-9)
    assert shifted_cholesky(-np.eye(3), (0.0,)) is None  # no shift allowed: no factor


def test_a_lower_factor_solves_and_inverts_like_an_upper_one(rng):
    """The lower and the upper Cholesky factor of one matrix solve the same system and give the same symmetric
    inverse (to rounding)."""
    from comanip.optim import shifted_cholesky

    A = rng.normal(size=(5, 5))
    matrix = A @ A.T + np.eye(5)
    upper, lower = shifted_cholesky(matrix, (0.0,)), shifted_cholesky(matrix, (0.0,), lower=True)
    b = rng.normal(size=5)
    np.testing.assert_allclose(lower.solve(b), upper.solve(b), rtol=1e-12)
    for factor in (upper, lower):
        inverse = factor.inverse()
        np.testing.assert_array_equal(inverse, inverse.T)
        np.testing.assert_allclose(inverse, np.linalg.inv(matrix), rtol=1e-10, atol=1e-12)


def test_a_row_major_matrix_gives_the_factor_of_its_column_major_copy(rng):
    """A C-ordered matrix is factored as its transpose (no reordering copy): the same system, either triangle read."""
    from comanip.optim import shifted_cholesky

    A = rng.normal(size=(40, 40))
    matrix = A @ A.T + np.eye(40)
    b = rng.normal(size=40)
    for lower in (False, True):
        row_major = shifted_cholesky(matrix, (0.0,), lower=lower)
        column_major = shifted_cholesky(np.asfortranarray(matrix), (0.0,), lower=lower)
        np.testing.assert_allclose(row_major.solve(b), column_major.solve(b), rtol=1e-12)
        np.testing.assert_allclose(row_major.inverse(), column_major.inverse(), rtol=1e-10, atol=1e-13)
    skewed = matrix.copy()
    skewed[np.tril_indices(40, -1)] = 1e3  # only the upper triangle is read (lower=False)
    np.testing.assert_allclose(shifted_cholesky(skewed, (0.0,)).solve(b), np.linalg.solve(matrix, b), rtol=1e-9)
