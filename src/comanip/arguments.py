"""Checks of user-given arguments, raised as ValueError before any solver work.

Each message names the argument, what was given and what is allowed.
"""

from __future__ import annotations

import math

import numpy as np


def as_vector(name: str, value, size: int, unit: str) -> np.ndarray:
    """value as a finite float array of shape (size,), else ValueError."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of {size} numbers ({unit}), got {value!r}") from None
    if array.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},) ({unit}), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite ({unit}), got {array.tolist()}")
    return array


def as_positive(name: str, value, unit: str) -> float:
    """value as a finite float > 0, else ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0 ({unit}), got {value!r}")
    return float(value)


def as_nonnegative(name: str, value, unit: str) -> float:
    """value as a finite float ≥ 0, else ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value) or value < 0:
        raise ValueError(f"{name} must be a finite number ≥ 0 ({unit}), got {value!r}")
    return float(value)


def as_positive_array(name: str, value, unit: str) -> np.ndarray:
    """value (a number or an array of any shape) as a float array, all finite and > 0, else ValueError."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number or array of numbers > 0 ({unit}), got {value!r}") from None
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite ({unit}); got NaN or inf in {array.tolist()}")
    if np.any(array <= 0):
        raise ValueError(f"{name} must be > 0 ({unit}), got {array.tolist()}")
    return array


def as_count(name: str, value, minimum: int = 1, unit: str = "", *, optional: bool = False) -> int | None:
    """value as an integer ≥ minimum (bool refused; None kept when ``optional``), else ValueError naming
    the argument and, if given, its unit (e.g. "processes")."""
    if optional and value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer ≥ {minimum}{f' ({unit})' if unit else ''}{' or None' if optional else ''}, "
                         f"got {value!r}")
    return int(value)


GOAL_WIDTH_RANGE_M = (1e-6, 1e3)
"""Goal widths w (m) a solve accepts: outside it the reward's peak under- or overflows in floating point."""


def as_goal_width(name: str, value) -> float:
    """A goal width w (m) as a float within GOAL_WIDTH_RANGE_M, else ValueError."""
    width = as_positive(name, value, "m")
    low, high = GOAL_WIDTH_RANGE_M
    if not low <= width <= high:
        raise ValueError(f"{name} must be between {low:g} and {high:g} m (goal width), got {value!r}")
    return width


def as_in_range(name: str, value, bounds: tuple[float, float], unit: str) -> float:
    """value as a finite float with low ≤ value ≤ high, else ValueError naming the range."""
    low, high = bounds
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not low <= value <= high:
        raise ValueError(f"{name} must be a number between {low:g} and {high:g} ({unit}), got {value!r}")
    return float(value)


MAGNITUDE_LIMIT = 1e6
"""Largest magnitude of a coordinate of a start state or goal a solve accepts (m, m/s, rad, rad/s): far past any
reach, and far from where squared distances overflow (a coordinate of 1.4e154)."""


def as_position(name: str, value, size: int) -> np.ndarray:
    """A task-space position (size,), m, finite and within ±MAGNITUDE_LIMIT per coordinate, else ValueError."""
    return as_bounded_vector(name, value, size, "task-space position, m")


def as_bounded_vector(name: str, value, size: int, unit: str) -> np.ndarray:
    """:func:`as_vector`, each entry also within ±MAGNITUDE_LIMIT, else ValueError."""
    array = as_vector(name, value, size, unit)
    if np.any(np.abs(array) > MAGNITUDE_LIMIT):
        raise ValueError(f"{name} must lie within ±{MAGNITUDE_LIMIT:g} per coordinate ({unit}), got {array.tolist()}")
    return array


def as_optional_positive(name: str, value, unit: str) -> float | None:
    return None if value is None else as_positive(name, value, unit)


def as_matrix(name: str, value, shape: tuple[int, ...], unit: str) -> np.ndarray:
    """value as a finite float array of the given shape, else ValueError."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a numeric array of shape {shape} ({unit}), got {value!r}") from None
    if array.shape != shape:
        raise ValueError(f"{name} must have shape {shape} ({unit}), got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite ({unit}); it holds NaN or inf")
    return array


def as_square_matrix(name: str, value, n: int, unit: str, positive_definite: bool = False) -> np.ndarray:
    """A scalar (times the identity) or an (n, n) finite matrix, optionally symmetric positive definite."""
    matrix = np.asarray(value, dtype=float)
    if matrix.ndim == 0:
        matrix = float(matrix) * np.eye(n)
    if matrix.shape != (n, n) or not np.all(np.isfinite(matrix)):
        raise ValueError(f"{name} must be a finite scalar or ({n}, {n}) matrix ({unit}), got shape {matrix.shape}")
    if positive_definite and (not np.allclose(matrix, matrix.T) or np.linalg.eigvalsh(matrix).min() <= 0):
        raise ValueError(f"{name} must be symmetric positive definite ({unit}), got {matrix.tolist()}")
    return matrix


def as_scheduler_address(name: str, value) -> str:
    """A Dask scheduler address (protocol://location; for tcp and tls, host:port as in 'tcp://host:8786'), else
    ValueError naming the argument."""
    text = value if isinstance(value, str) else ""
    protocol, _, location = text.partition("://")
    host, _, port = location.rpartition(":")
    if not (protocol and location) or (protocol in ("tcp", "tls") and not (host and port.isdigit())):
        raise ValueError(f"{name} must be a Dask scheduler address such as 'tcp://host:8786' (protocol://host:port), "
                         f"got {value!r}")
    return text
