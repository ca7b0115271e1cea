"""From raw samples of a hand to a :class:`~comanip.recordings.recording.Recording`.

1. **Resampling** (:func:`resample`): raw samples come at irregular times, and event-driven devices (a mouse)
   send none while the hand is still. Samples at one time are averaged; a gap longer than ``hold_gap`` is a
   pause (the hand stayed where the earlier sample was until one ``step`` before the next sample); positions
   are then interpolated linearly onto a uniform grid of step ``step``.
2. **Velocity** (:func:`smoothed`): a Savitzky–Golay filter (polynomial ``order`` over ``window`` seconds)
   smooths the positions and differentiates them.
3. **Onset and end** (:func:`movement_bounds`): with v_peak the largest speed, the onset is the first time
   the speed exceeds ``onset_fraction``·v_peak, moved back to where it last was below half of that; the end is
   the first time after the last sample above ``end_fraction``·v_peak. A pause followed by a corrective
   sub-movement is inside the movement: the end comes after the last sub-movement.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import savgol_filter

from comanip.arguments import as_positive
from comanip.recordings.recording import Recording

STEP = 0.01
"""Default sampling step after resampling (s)."""
WINDOW = 0.05
"""Default Savitzky–Golay window (s)."""
ORDER = 2
"""Default Savitzky–Golay polynomial order."""
HOLD_GAP = 0.05
"""Default gap between raw samples (s) beyond which the hand is taken to have paused."""
ONSET_FRACTION = 0.05
"""Default onset and end threshold, a fraction of the peak speed (docs/formulation.md §6 defines MT so)."""


def resample(t, position, step: float = STEP, hold_gap: float = HOLD_GAP) -> tuple[np.ndarray, np.ndarray]:
    """Positions on a uniform grid (times (K,) s from the first raw sample, positions (K, d) m).

    Args:
        t: raw sample times (N,), s, non-decreasing.
        position: raw positions (N, d).
        step: grid step (s).
        hold_gap: a gap between raw samples longer than this (s) is a pause (module docstring).
    """
    t = np.asarray(t, dtype=float)
    position = np.asarray(position, dtype=float)
    step = as_positive("step", step, "s")
    hold_gap = as_positive("hold_gap", hold_gap, "s")
    if t.ndim != 1 or position.ndim != 2 or position.shape[0] != t.size or t.size < 2:
        raise ValueError(f"resample needs times (N,) and positions (N, d) with N ≥ 2, got shapes {t.shape} and {position.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(position))):
        raise ValueError("resample needs finite times and positions")
    if np.any(np.diff(t) < 0):
        raise ValueError("resample needs non-decreasing times")
    times, first = np.unique(t, return_index=True)
    counts = np.diff(np.r_[first, t.size])
    averaged = np.add.reduceat(position, first, axis=0) / counts[:, None]
    gaps = np.flatnonzero(np.diff(times) > hold_gap)
    if gaps.size:      # the hand held still until one step before the sample after the pause
        times = np.insert(times, gaps + 1, times[gaps + 1] - step)
        averaged = np.insert(averaged, gaps + 1, averaged[gaps], axis=0)
    times = times - times[0]
    grid = np.arange(0.0, times[-1] + 0.5 * step, step)
    return grid, np.column_stack([np.interp(grid, times, column) for column in averaged.T])


def smoothed(position: np.ndarray, step: float, window: float = WINDOW, order: int = ORDER) -> tuple[np.ndarray, np.ndarray]:
    """Savitzky–Golay smoothed positions (K, d) and velocities (K, d) (per s) of uniformly sampled positions."""
    samples = max(order + 2 - order % 2, 2 * int(round(window / step / 2)) + 1)
    if position.shape[0] < samples:
        return position.copy(), np.gradient(position, step, axis=0)
    smooth = savgol_filter(position, samples, order, axis=0, mode="interp")
    return smooth, savgol_filter(position, samples, order, deriv=1, delta=step, axis=0, mode="interp")


def movement_bounds(t: np.ndarray, velocity: np.ndarray, onset_fraction: float = ONSET_FRACTION,
                    end_fraction: float = ONSET_FRACTION) -> tuple[float, float]:
    """(onset, end) in s on ``t`` (module docstring, step 3) from velocities (K, d)."""
    speed = np.linalg.norm(velocity, axis=1)
    peak = float(speed.max())
    if peak <= 0:
        raise ValueError("the recording never moves: no onset")
    above = np.flatnonzero(speed > onset_fraction * peak)
    first = int(above[0])
    quiet = np.flatnonzero(speed[:first] <= 0.5 * onset_fraction * peak)
    onset = int(quiet[-1]) if quiet.size else max(first - 1, 0)
    last = int(np.flatnonzero(speed > end_fraction * peak)[-1])
    end = min(last + 1, len(t) - 1)
    return float(t[onset]), float(t[end])


def recording_from_samples(name: str, t, position, *, step: float = STEP, window: float = WINDOW, order: int = ORDER,
                           hold_gap: float = HOLD_GAP, onset_fraction: float = ONSET_FRACTION, width: float | None = None,
                           target=None) -> Recording:
    """A :class:`Recording` from raw samples: resampled, smoothed and cut at the movement's end (module docstring).

    Args:
        name: the movement's identifier.
        t: raw sample times (N,), s.
        position: raw positions (N, d), m.
        step: resampling step (s).
        window: Savitzky–Golay window (s).
        order: Savitzky–Golay polynomial order.
        hold_gap: a gap between raw samples longer than this (s) is a pause.
        onset_fraction: onset and end threshold, a fraction of the peak speed.
        width: target width (m) when known.
        target: the target (d,), m, when known.
    """
    grid, resampled = resample(t, position, step, hold_gap)
    smooth, velocity = smoothed(resampled, step, window, order)
    onset, end = movement_bounds(grid, velocity, onset_fraction)
    keep = grid <= end + 1e-9
    return Recording(name=name, t=grid[keep], position=smooth[keep], velocity=velocity[keep], onset=onset, end_time=end,
                     width=width, target=None if target is None else np.asarray(target, dtype=float))
