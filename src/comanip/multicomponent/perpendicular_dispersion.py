"""Perpendicular dispersion of reaches over path progress, and its peak: the transition point (docs/formulation.md §8).

Reaches go from a common start x_0 to a goal g (d,), m, along the unit direction u = (g - x_0) / D,
D = ||g - x_0||. A hand position x splits into progress p = (x - x_0)·u (m along the path) and a
perpendicular deviation e = (x - x_0) - p u (d,). Every trial is read at the first time its progress
reaches each grid value p ∈ [0, D] (a hand that overshoots and comes back is not counted twice), and the
perpendicular dispersion at p is the spread of e over trials, sqrt(Σ_k var(e_k)) in m. Peternel & Babič
(2019) take the point of peak perpendicular dispersion as the transition from the fast initial
sub-movement to the corrective one; its distance from the goal is D - p_peak.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_count, as_vector


@dataclass
class DispersionProfile:
    """Perpendicular dispersion of N trials over P points of path progress."""

    progress: np.ndarray
    """Progress along the start→goal line (P,), m, from 0 to D."""
    dispersion: np.ndarray
    """Perpendicular dispersion (P,), m; NaN where fewer than half the trials reached that progress."""
    reached: np.ndarray
    """Trials that reached each progress value (P,)."""
    goal_distance: float
    """D = ||goal - start||, m."""
    peak_progress: float
    """Progress of the dispersion peak, m (refined between grid points by a parabola)."""
    peak_dispersion: float
    """Dispersion at the peak, m."""

    @property
    def distance_to_goal(self) -> np.ndarray:
        """D - progress (P,), m."""
        return self.goal_distance - self.progress

    @property
    def transition_distance(self) -> float:
        """Distance of the dispersion peak from the goal, D - p_peak, m."""
        return self.goal_distance - self.peak_progress

    @property
    def has_interior_peak(self) -> bool:
        """True when the peak lies strictly inside the path and the dispersion falls after it."""
        valid = np.flatnonzero(np.isfinite(self.dispersion))
        peak = int(np.nanargmax(self.dispersion))
        return valid[0] < peak < valid[-1] and self.dispersion[valid[-1]] < self.peak_dispersion


def perpendicular_dispersion_profile(paths, goal, n_points: int = 101) -> DispersionProfile:
    """Dispersion profile of hand paths (N, K+1, d), m, that all start at paths[:, 0] and aim at goal (d,), m.

    Trials may differ in length K only through NaN padding at the end. n_points (≥ 3) grid values of progress
    are spread evenly over [0, D].
    """
    grid, deviations = first_passage_deviations(paths, goal, n_points)
    return profile_from_deviations(grid, deviations)


def first_passage_deviations(paths, goal, n_points: int = 101) -> tuple[np.ndarray, np.ndarray]:
    """Progress grid (P,) over [0, D], m, and each trial's perpendicular deviation there (N, P, d), m.

    NaN where a trial never reaches that progress. Arguments as :func:`perpendicular_dispersion_profile`.
    """
    paths = np.asarray(paths, dtype=float)
    if paths.ndim != 3 or paths.shape[0] < 2 or paths.shape[1] < 2:
        raise ValueError(f"paths must have shape (trials ≥ 2, samples ≥ 2, d) in m, got shape {paths.shape}")
    goal = as_vector("goal", goal, paths.shape[2], "m")
    if not np.allclose(paths[:, 0], paths[0, 0], atol=1e-12):
        raise ValueError("paths must share their first point (the start); they differ at sample 0")
    as_count("n_points", n_points, 3)
    start = paths[0, 0]
    D = float(np.linalg.norm(goal - start))
    if D <= 0:
        raise ValueError(f"goal must differ from the start {start.tolist()}, got {goal.tolist()}")
    u = (goal - start) / D
    offsets = paths - start
    along = offsets @ u                                   # (N, K+1)
    perpendicular = offsets - along[..., None] * u        # (N, K+1, d)
    grid = np.linspace(0.0, D, n_points)
    return grid, np.stack([values_at_first_passage(a, e, grid) for a, e in zip(along, perpendicular)])


def profile_from_deviations(grid: np.ndarray, deviations: np.ndarray) -> DispersionProfile:
    """The profile of first-passage deviations (N, P, d), m, over the progress grid (P,), m."""
    reached = np.sum(np.isfinite(deviations[..., 0]), axis=0)
    enough = reached >= max(2, (len(deviations) + 1) // 2)
    dispersion = np.full(len(grid), np.nan)
    variance = np.nanvar(deviations[:, enough], axis=0, ddof=1)   # (P', d)
    dispersion[enough] = np.sqrt(np.sum(variance, axis=-1))
    peak_progress, peak_dispersion = _refined_peak(grid, dispersion)
    return DispersionProfile(progress=grid, dispersion=dispersion, reached=reached, goal_distance=float(grid[-1]),
                             peak_progress=peak_progress, peak_dispersion=peak_dispersion)


def bootstrap_transition_std(grid: np.ndarray, deviations: np.ndarray, rng: np.random.Generator,
                             n_resamples: int = 200) -> float:
    """Standard error (m) of the transition distance, by resampling the trials of deviations (N, P, d)."""
    n = len(deviations)
    distances = [profile_from_deviations(grid, deviations[rng.integers(0, n, n)]).transition_distance
                 for _ in range(n_resamples)]
    return float(np.std(distances, ddof=1))


def values_at_first_passage(along: np.ndarray, perpendicular: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Values (P, d) of a per-sample quantity perpendicular (K+1, d) (e.g. the perpendicular deviation, m, or
    a speed) at the first time progress along (K+1,) reaches each grid value (P,).

    Linear in time between samples; NaN for grid values the trial never reaches.
    """
    finite = np.isfinite(along)
    along, perpendicular = along[finite], perpendicular[finite]
    record = np.maximum.accumulate(along)
    k = np.searchsorted(record, grid, side="left")      # first sample whose progress reaches the grid value
    out = np.full((len(grid), perpendicular.shape[1]), np.nan)
    inside = k < len(along)
    k_in = k[inside]
    before = np.maximum(k_in - 1, 0)
    # on the segment before k progress climbs from along[k-1] (≤ the record, < grid value) to along[k] (≥ it)
    span = along[k_in] - along[before]
    fraction = np.where(span > 0, (grid[inside] - along[before]) / np.where(span > 0, span, 1.0), 1.0)
    fraction = np.clip(fraction, 0.0, 1.0)[:, None]
    out[inside] = perpendicular[before] + fraction * (perpendicular[k_in] - perpendicular[before])
    return out


def _refined_peak(grid: np.ndarray, values: np.ndarray) -> tuple[float, float]:
    """Location and height of the maximum of values over grid, refined by a parabola through its neighbours."""
    i = int(np.nanargmax(values))
    if 0 < i < len(values) - 1 and np.all(np.isfinite(values[i - 1 : i + 2])):
        left, centre, right = values[i - 1 : i + 2]
        curvature = left - 2 * centre + right
        if curvature < 0:
            shift = 0.5 * (left - right) / curvature     # in grid steps, within (-0.5, 0.5) at a maximum
            step = grid[1] - grid[0]
            return float(grid[i] + shift * step), float(centre - 0.25 * (left - right) * shift)
    return float(grid[i]), float(values[i])
