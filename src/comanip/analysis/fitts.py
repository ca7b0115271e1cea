"""Fitts' law analysis: movement time against the index of difficulty, with a least-squares line.

For a reach of distance D (m) to a goal of width w (m):

- Fitts form:   ID = log2(2D / w)   (bits)
- Shannon form: ID = log2(D / w + 1) (bits)

and MT = a + b·ID is fitted by ordinary least squares (a in s, b in s/bit), with R² its coefficient of
determination. The trend checks say whether a wider goal is reached no slower at a fixed distance and a
farther one no faster at a fixed width (paper Section IV-D).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.stats import linregress

FITTS_FORMS = ("fitts", "shannon")


def index_of_difficulty(distance, width, form: str = "fitts") -> np.ndarray:
    """ID (bits) for distances and widths (m, broadcast together), in the Fitts or Shannon form."""
    if form not in FITTS_FORMS:
        raise ValueError(f"form must be one of {FITTS_FORMS}, got {form!r}")
    distance = np.asarray(distance, dtype=float)
    width = np.asarray(width, dtype=float)
    if np.any(~np.isfinite(distance)) or np.any(distance <= 0) or np.any(~np.isfinite(width)) or np.any(width <= 0):
        raise ValueError(f"distance and width must be finite and > 0 (m), got {distance.tolist()} and {width.tolist()}")
    if form == "fitts":
        return np.log2(2.0 * distance / width)
    return np.log2(distance / width + 1.0)


@dataclass(frozen=True)
class FittsFit:
    """MT = a + b·ID fitted over the conditions whose MT is finite."""

    form: str
    """'fitts' or 'shannon'."""
    a: float
    """Intercept (s)."""
    b: float
    """Slope (s/bit)."""
    r2: float
    """Coefficient of determination of the line (NaN with fewer than 3 points or constant ID)."""
    n_points: int
    """Conditions used (those with a finite movement time)."""

    def predict(self, distance, width) -> np.ndarray:
        """Movement time (s) the line predicts for distances and widths (m)."""
        return self.a + self.b * index_of_difficulty(distance, width, self.form)

    def to_dict(self) -> dict:
        return asdict(self)


def fit_fitts(distances, widths, movement_times, form: str = "fitts") -> FittsFit:
    """Least-squares MT = a + b·ID over conditions: distances, widths (k,) m, movement_times (k,) s (NaN skipped)."""
    distances, widths, movement_times = (np.asarray(v, dtype=float).ravel() for v in (distances, widths, movement_times))
    if not distances.shape == widths.shape == movement_times.shape:
        raise ValueError(f"distances, widths and movement_times must have one entry per condition, got sizes "
                         f"{distances.size}, {widths.size}, {movement_times.size}")
    ids = index_of_difficulty(distances, widths, form)
    keep = np.isfinite(movement_times)
    x, y = ids[keep], movement_times[keep]
    if keep.sum() < 3 or np.ptp(x) == 0:
        return FittsFit(form, np.nan, np.nan, np.nan, int(keep.sum()))
    line = linregress(x, y)
    r2 = float(line.rvalue**2) if np.ptp(y) > 0 else np.nan
    return FittsFit(form, float(line.intercept), float(line.slope), r2, int(keep.sum()))


def trend_fraction(values, increasing: bool, tolerance: float = 0.0) -> float:
    """Fraction of neighbouring pairs along the last axis of values (..., k) that follow the trend.

    A pair follows an increasing trend when values[j+1] ≥ values[j] - tolerance (decreasing: ≤ + tolerance).
    Pairs with a NaN count as not following. Returns NaN when there are no pairs.
    """
    values = np.asarray(values, dtype=float)
    change = np.diff(values, axis=-1)
    if change.size == 0:
        return np.nan
    follows = change >= -tolerance if increasing else change <= tolerance
    return float(np.mean(follows & np.isfinite(change)))
