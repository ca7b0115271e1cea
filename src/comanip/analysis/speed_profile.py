"""Speed-profile metrics of one reach (docs/formulation.md §6): time of peak speed, movement time, asymmetry.

For a speed profile v(t_i) = ||d mu_x/dt|| sampled at uniform times t_i (s):

- t_peak: the time of the largest sample, refined by the parabola through it and its two neighbours;
- MT (movement time): the first time after the peak at which v falls below 5 % of the peak speed,
  interpolated linearly between the two samples that straddle the threshold;
- asymmetry: t_peak / MT.

The refinements keep the metrics from being quantised to the step h: with h = 0.02 s and MT ≈ 0.3 s a
one-sample shift of the peak moves t_peak/MT by 0.07, more than the effects the validation measures.
Under this MT definition a minimum-jerk reach has t_peak/MT = 0.532, not 0.5 (its speed falls below
5 % of the peak at 94 % of its duration; see :mod:`comanip.analysis.minimum_jerk_baseline`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

SETTLING_FRACTION = 0.05
"""Fraction of the peak speed below which a reach counts as finished (docs/formulation.md §6)."""


@dataclass(frozen=True)
class SpeedMetrics:
    """Timing of one speed profile; times in s from the start of the profile, speeds in m/s."""

    t_peak: float
    """Time of peak speed (s)."""
    peak_speed: float
    """Peak speed (m/s)."""
    movement_time: float
    """MT (s): first time after the peak with speed below the settling fraction of the peak; NaN when the
    profile never falls that low (the reach did not finish within the samples)."""
    asymmetry: float
    """t_peak / MT (NaN when MT is NaN); 0.5 means the peak sits at mid-movement."""

    @property
    def settled(self) -> bool:
        """True when the speed fell below the settling fraction of its peak within the profile."""
        return bool(np.isfinite(self.movement_time))

    def to_dict(self) -> dict:
        return asdict(self) | {"settled": self.settled}


def speed_metrics(t, speed, settling_fraction: float = SETTLING_FRACTION) -> SpeedMetrics:
    """Metrics of a speed profile: t (T,) uniformly spaced times (s), speed (T,) ≥ 0 (m/s), T ≥ 3."""
    t = np.asarray(t, dtype=float)
    speed = np.asarray(speed, dtype=float)
    if t.ndim != 1 or t.shape != speed.shape or len(t) < 3:
        raise ValueError(f"t and speed must be 1-D arrays of the same length ≥ 3, got shapes {t.shape} and {speed.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(speed))):
        raise ValueError("t and speed must be finite; they hold NaN or inf")
    steps = np.diff(t)
    if np.any(steps <= 0) or not np.allclose(steps, steps[0], rtol=1e-6):
        raise ValueError(f"t must be uniformly increasing (s), got steps from {steps.min()} to {steps.max()}")
    if not 0 < settling_fraction < 1:
        raise ValueError(f"settling_fraction must be in (0, 1), got {settling_fraction!r}")
    h = steps[0]
    k = int(np.argmax(speed))
    t_peak, peak = t[k], speed[k]
    if 0 < k < len(t) - 1:
        before, after = speed[k - 1], speed[k + 1]
        curvature = before - 2 * peak + after
        if curvature < 0:
            offset = 0.5 * (before - after) / curvature
            t_peak = t[k] + offset * h
            peak = peak - 0.25 * (before - after) * offset
    threshold = settling_fraction * peak
    below = np.nonzero(speed[k + 1 :] < threshold)[0]
    if len(below) == 0:
        return SpeedMetrics(float(t_peak), float(peak), np.nan, np.nan)
    j = k + 1 + int(below[0])
    movement_time = t[j - 1] + h * (speed[j - 1] - threshold) / (speed[j - 1] - speed[j])
    return SpeedMetrics(float(t_peak), float(peak), float(movement_time), float(t_peak / movement_time))



@dataclass(frozen=True)
class ReachTiming:
    """Timing of one movement as recorded movements are timed (:func:`movement_timing`): times in s, speeds in m/s."""

    onset: float
    """Start of the movement (s from the start of the profile)."""
    movement_time: float
    """MT (s) from the onset to the end; NaN when the speed is above the end threshold at the last sample."""
    peak_fraction: float
    """(t_peak − onset) / MT: how early in the movement the speed peaks (NaN when MT is NaN)."""
    peak_speed: float
    """Peak speed (m/s)."""


def movement_timing(t, speed, fraction: float = SETTLING_FRACTION) -> ReachTiming:
    """Onset, MT and t_peak/MT of a speed profile by the rule recorded movements are cut by
    (:func:`comanip.recordings.preprocessing.movement_bounds`), interpolated between samples so that they change
    smoothly with the profile: the onset where the speed last rose through half of ``fraction``·v_peak before it first
    exceeds ``fraction``·v_peak (t[0] when it starts above that); the end where it falls through ``fraction``·v_peak
    after its last sample above it, so a corrective sub-movement is inside the movement; t_peak refined as in
    :func:`speed_metrics`. t (T,) uniformly spaced times (s), speed (T,) ≥ 0 (m/s), T ≥ 3."""
    metrics = speed_metrics(t, speed, fraction)
    t = np.asarray(t, dtype=float)
    speed = np.asarray(speed, dtype=float)
    threshold = fraction * metrics.peak_speed
    first = int(np.argmax(speed > threshold))
    quiet = np.flatnonzero(speed[:first] <= 0.5 * threshold)
    onset = t[0] if not quiet.size else _crossing(t, speed, int(quiet[-1]), 0.5 * threshold)
    last = int(np.flatnonzero(speed > threshold)[-1])
    if last == len(t) - 1:
        return ReachTiming(float(onset), np.nan, np.nan, metrics.peak_speed)
    duration = _crossing(t, speed, last, threshold) - onset
    return ReachTiming(float(onset), float(duration), float((metrics.t_peak - onset) / duration), metrics.peak_speed)


def _crossing(t: np.ndarray, speed: np.ndarray, k: int, level: float) -> float:
    """The time between samples k and k + 1 where the speed passes ``level``, linearly interpolated."""
    return float(t[k] + (t[k + 1] - t[k]) * (level - speed[k]) / (speed[k + 1] - speed[k]))
