"""A recorded aimed movement: the hand's positions and velocities on a uniform time grid, with its onset and end.

Shapes: K samples, d task dimensions (2 for a screen or a table top, 3 for a reach in space).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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

    def seen_until(self, fraction: float) -> int:
        """Number of samples observed when ``fraction`` of the movement time has passed since the onset."""
        return int(np.searchsorted(self.t, self.onset + fraction * self.movement_time, side="right"))
