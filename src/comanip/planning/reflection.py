"""The reflection that turns a reach along e_1 onto any direction: the symmetry by which the reach library and the
estimators' reach family reuse one solved reach of an isotropic point mass for every direction."""

from __future__ import annotations

import numpy as np


def reflection_onto(direction: np.ndarray) -> np.ndarray:
    """Orthogonal (d, d) matrix taking e_1 to the unit vector ``direction`` (d,): a Householder reflection
    (the identity when direction is e_1). Reflections are symmetries too: the isotropic model has no
    handedness."""
    d = direction.size
    v = np.eye(d)[0] - direction
    norm2 = float(v @ v)
    if norm2 < 1e-24:
        return np.eye(d)
    return np.eye(d) - 2.0 * np.outer(v, v) / norm2
