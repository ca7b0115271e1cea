"""The shifted Cholesky factorisation (comanip.optim.factorisation)."""

import numpy as np


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
