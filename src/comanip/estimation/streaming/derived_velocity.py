"""The hand's velocity from its positions alone, for a tracker that sends no velocity: one sample at a time, causal.

The rule is the one :meth:`comanip.recordings.motion_capture.TrackedSamples.stream` streams recorded trials with
(what the people model is fitted on): the newest position minus the newest one at least ``window`` seconds
earlier, over the time between them, a backward difference whose span sets both its lag (about window / 2) and
its noise (a position noise sigma gives a velocity noise of about sqrt(2)·sigma / window). Until the stream is
``window`` long the difference spans what there is, and a stream's first position has velocity 0 (the hand is
taken at rest where a stream starts). A gap longer than ``restart_after`` starts the stream over.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from comanip.arguments import as_positive
from comanip.recordings.motion_capture import VELOCITY_WINDOW_S


class DerivedVelocity:
    """Velocities (d,) m/s of a stream of positions (d,) m, one :meth:`add` per position (module docstring).

    Args:
        window: the backward difference's span (s, > 0).
        restart_after: a gap between two positions longer than this (s) starts the stream over; None: never.
    """

    def __init__(self, window: float = VELOCITY_WINDOW_S, restart_after: float | None = None):
        self.window = as_positive("window", window, "s")
        self.restart_after = None if restart_after is None else as_positive("restart_after", restart_after, "s")
        self._kept: deque[tuple[float, np.ndarray]] = deque()

    def restart(self) -> None:
        """Forget the positions so far: the next one starts a stream."""
        self._kept.clear()

    def add(self, stamp: float, position) -> np.ndarray:
        """The velocity (d,) m/s at the position (d,) m stamped ``stamp`` (s, after the previous one's)."""
        stamp, position = float(stamp), np.asarray(position, dtype=float)
        kept = self._kept
        if kept and not stamp > kept[-1][0]:
            raise ValueError(f"stamps must increase from position to position: got {stamp:g} s after {kept[-1][0]:g} s")
        if kept and self.restart_after is not None and stamp - kept[-1][0] > self.restart_after:
            kept.clear()
        # keep the newest position at least the window earlier and those after it
        while len(kept) > 1 and kept[1][0] <= stamp - self.window + 1e-9:
            kept.popleft()
        earlier = kept[0] if kept else None
        kept.append((stamp, position))
        if earlier is None:
            return np.zeros_like(position)
        return (position - earlier[1]) / (stamp - earlier[0])
