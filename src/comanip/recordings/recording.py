"""A recorded aimed movement: the hand's positions and velocities on a uniform time grid, with its onset and end.

Shapes: K samples, d task dimensions (2 for a screen or a table top, 3 for a reach in space).
"""

from __future__ import annotations

from dataclasses import dataclass

import warnings

import numpy as np

from comanip.units import check_positions_m, check_times_s


@dataclass(frozen=True)
class Recording:
    """One movement, preprocessed (:mod:`comanip.recordings.preprocessing`).

    The movement proper runs from ``onset`` to ``end_time``; samples before the onset show the hand at rest
    (or the recording's first sample when it starts with the movement), samples after the end are dropped.
    """

    name: str
    """Identifier of the movement (a trial name, or ``"<source>/<index>"``)."""
    t: np.ndarray
    """Sample times (K,), s since the recording's first sample, uniform step ``step``."""
    position: np.ndarray
    """Hand positions (K, d), m."""
    velocity: np.ndarray
    """Hand velocities (K, d), m/s (Savitzky–Golay derivative of the positions)."""
    onset: float
    """Movement onset (s, on ``t``): the speed first rises above the onset threshold here."""
    end_time: float
    """Movement end (s, on ``t``): the speed stays below the end threshold from here on."""
    width: float | None = None
    """Target width (m) when known."""
    target: np.ndarray | None = None
    """The target the person aimed at (d,), m, when known (the endpoint ``end`` is where the hand stopped)."""

    def __post_init__(self):
        t, position, velocity = (np.asarray(a, dtype=float) for a in (self.t, self.position, self.velocity))
        if t.ndim != 1 or t.size < 2 or position.ndim != 2 or position.shape[0] != t.size or velocity.shape != position.shape:
            raise ValueError(f"recording {self.name!r} needs times (K,), positions (K, d) and velocities (K, d) with K ≥ 2, "
                             f"got shapes {t.shape}, {position.shape} and {velocity.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(position)) and np.all(np.isfinite(velocity))):
            raise ValueError(f"recording {self.name!r} holds NaN or inf; a lost sample is a gap: leave it out")
        if np.any(np.diff(t) <= 0):
            raise ValueError(f"recording {self.name!r}: times must increase from sample to sample (s)")
        step = float(np.median(np.diff(t)))
        if not (t[0] - 2 * step <= self.onset <= self.end_time <= t[-1] + 2 * step):
            raise ValueError(f"recording {self.name!r}: onset {self.onset:g} s and end {self.end_time:g} s must lie in "
                             f"order within its times {t[0]:g}..{t[-1]:g} s (give or take two samples)")
        for check, values, what in ((check_times_s, t, "times"), (check_positions_m, position, "positions")):
            try:
                check(values, f"recording {self.name!r}, {what}")
            except ValueError as error:      # valid numbers a person hardly makes: say so, do not refuse
                warnings.warn(str(error), stacklevel=3)
        for name, value in (("t", t), ("position", position), ("velocity", velocity)):
            object.__setattr__(self, name, value)

    @property
    def step(self) -> float:
        """Sampling step (s)."""
        return float(self.t[1] - self.t[0])

    @property
    def start(self) -> np.ndarray:
        """Hand position at the onset (d,), m."""
        return self.position_at(self.onset)

    @property
    def end(self) -> np.ndarray:
        """Hand position at the end (d,), m: the movement's endpoint."""
        return self.position_at(self.end_time)

    @property
    def distance(self) -> float:
        """|end - start| (m), the movement's amplitude D."""
        return float(np.linalg.norm(self.end - self.start))

    @property
    def movement_time(self) -> float:
        """MT = end_time - onset (s)."""
        return self.end_time - self.onset

    def position_at(self, time_s: float) -> np.ndarray:
        """Hand position (d,), m, at ``time_s`` (s on ``t``), linearly interpolated."""
        return np.array([np.interp(time_s, self.t, column) for column in self.position.T])

    def states_from_onset(self, d: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The movement's samples as an observations CSV holds them: times (K,) s from the onset (the first is
        the onset, t = 0) and states (K, 2d) [position m; velocity m/s] of the first ``d`` axes (None: all)."""
        d = self.position.shape[1] if d is None else d
        keep = self.t >= self.onset - 1e-9
        return self.t[keep] - self.onset, np.hstack([self.position[keep, :d], self.velocity[keep, :d]])

    def seen_until(self, fraction: float) -> int:
        """Number of samples observed when ``fraction`` of the movement time has passed since the onset."""
        return int(np.searchsorted(self.t, self.onset + fraction * self.movement_time, side="right"))
