"""How the value of reaching the goal decays with time (the cost–benefit trade-off's time cost).

``exponential`` (default, the paper): weight gamma^i at step i.
``hyperbolic``: weight 1 / (1 + k i) with k = 1/gamma - 1, the hyperbola with the same initial slope;
it discounts the far future less steeply (Shadmehr et al. 2010 argue people discount hyperbolically).
"""

from __future__ import annotations

import numpy as np

DISCOUNT_FORMS = ("exponential", "hyperbolic")


def check_discount_form(form: str) -> str:
    if form not in DISCOUNT_FORMS:
        raise ValueError(f"discount must be one of {DISCOUNT_FORMS}, got {form!r}")
    return form


def discount_weights(gamma: float, H: int, form: str = "exponential") -> np.ndarray:
    """Weights (H+1,) for steps 0..H."""
    check_discount_form(form)
    i = np.arange(H + 1, dtype=float)
    if form == "exponential":
        return gamma**i
    return 1.0 / (1.0 + (1.0 / gamma - 1.0) * i)
