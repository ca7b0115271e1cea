"""The working set's constrained step (comanip.optim.active_set)."""

import numpy as np


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
