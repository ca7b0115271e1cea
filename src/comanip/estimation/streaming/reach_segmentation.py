"""Rests and reaches in an uninterrupted stream of a hand: rest, reach, rest, the next reach, with no reset.

A robot beside a person sees one stream of hand samples (times s, positions m, velocities m/s) in which the
person makes one reach after another and rests in between. :class:`ReachSegmenter` segments it from the motion
itself (:mod:`comanip.estimation.hand_rest`: rest is judged from positions, which a tracker's noise does not
make move):

1. **At rest.** The last ``lead + window`` seconds of samples are kept. The rest position is where the hand
   rests (the mean of its positions over the window while they stay within ``radius`` of it and drift slower
   than ``creep``), or its first sample until it has rested for a window.
2. **A reach starts** when a sample lies farther than ``radius`` from the rest position and the hand moves
   faster than ``start_speed`` (a drift or the return after an overshoot is not a reach): it starts from the
   rest position at rest, its clock at the first kept sample of the last ``lead`` seconds, and those samples
   are its first observations.
3. **The reach ends** when the hand rests again (as in 1, over a window that lies after the sample that
   started the reach), and the stream is at rest again (1).

:class:`~comanip.estimation.streaming.estimation_loop.EstimationLoop` runs a goal estimator over the reaches it finds.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_positive
from comanip.estimation.people.endpoint_baselines import MOVING_SPEED
from comanip.estimation.hand_rest import (REST_RADIUS_M, REST_WINDOW_S, fitted_velocity, has_left, resting_position,
                                          too_far_apart_to_rest)

START_SPAN = 0.05
"""Span (s) of the positions whose fitted velocity tells a reach leaving its rest from a drift."""
LEAD_S = 0.15
"""Default time (s) before a reach leaves the rest radius whose samples it begins with (the hand at rest, then
its onset)."""


@dataclass(frozen=True)
class SegmentationSettings:
    """How a stream is split into rests and reaches (module docstring)."""

    radius: float = REST_RADIUS_M
    """A sample farther than this (m) from the rest position starts a reach; a hand whose positions stay
    within it of their mean for ``window`` seconds rests (:mod:`comanip.estimation.hand_rest`)."""
    window: float = REST_WINDOW_S
    """How long (s) the hand must stay still to rest."""
    lead: float = LEAD_S
    """How much of the rest before a reach (s) the reach begins with."""
    start_speed: float = 0.1
    """A reach leaves its rest faster than this (m/s, the velocity of a line fitted to the last ``START_SPAN``
    seconds of positions, at least three): a slower departure (a drift, the return after an overshoot) is not
    a new reach."""
    creep: float = MOVING_SPEED
    """A hand moving slower than this (m/s, the slope of a line fitted to its positions over the window) is at
    rest even while it drifts: the rest position follows it, and no drift, however long, starts a reach."""

    def __post_init__(self):
        as_positive("radius", self.radius, "m")
        as_positive("creep", self.creep, "m/s")
        as_positive("start_speed", self.start_speed, "m/s")
        as_positive("window", self.window, "s")
        as_positive("lead", self.lead, "s")


@dataclass(frozen=True)
class ReachStart:
    """A reach the segmenter has just found."""

    number: int
    """Reaches started so far, this one included (1 for the first)."""
    start: np.ndarray
    """The rest position it starts from (d,), m."""
    clock: float
    """Stream time (s) of the reach's time 0: its first sample."""
    samples: list
    """Its samples so far, (stream time s, position (d,) m, velocity (d,) m/s), from its time 0 to the one
    that started it."""


class ReachSegmenter:
    """Rest and reaches in a stream of samples (module docstring, steps 1-3); cheap enough for every sample.

    Args:
        settings: :class:`SegmentationSettings`.
    """

    def __init__(self, settings: SegmentationSettings | None = None):
        self.settings = settings or SegmentationSettings()
        if not isinstance(self.settings, SegmentationSettings):
            raise ValueError(f"settings must be a SegmentationSettings, got {type(self.settings).__name__}")
        self.reset()

    def reset(self) -> None:
        """Start over: at rest, no reach, nothing kept."""
        self._kept: deque = deque()              # (t, position, velocity): the rest so far, or the reach's last window
        self._rest: np.ndarray | None = None
        self._departure = np.inf                 # stream time (s) of the sample that started the reach under way
        self.reaches = 0
        """Reaches started so far."""
        self.moving = False
        """True while a reach is under way."""

    def update(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> ReachStart | None:
        """Add a sample (stream time s, position (d,) m, velocity (d,) m/s); the reach it starts, else None.
        Afterwards :attr:`moving` says whether a reach is under way (False once the sample ended one)."""
        s = self.settings
        self._kept.append((time_s, position, velocity))
        span = s.window if self.moving else s.lead + s.window
        while len(self._kept) > 1 and self._kept[1][0] <= time_s - span:   # keep one sample at or before the span
            self._kept.popleft()
        if self.moving:
            kept = [k for k in self._kept if k[0] >= self._departure]
            resting = None if len(kept) < len(self._kept) else self._resting(kept)
            if resting is not None:
                self.moving, self._rest = False, resting
            return None
        resting = self._resting(self._kept)
        if resting is not None or self._rest is None:
            self._rest = np.array(position, dtype=float) if resting is None else resting
            return None
        if not has_left(np.asarray(position)[None], self._rest, s.radius) or self._departing_speed() < s.start_speed:
            return None
        lead = [k for k in self._kept if k[0] >= time_s - s.lead - 1e-9]
        self.reaches, self.moving, self._departure = self.reaches + 1, True, time_s
        return ReachStart(self.reaches, self._rest.copy(), lead[0][0], lead)

    def _departing_speed(self) -> float:
        """Speed (m/s) of a line fitted to the kept positions of the last START_SPAN s (at least the last three)."""
        kept = list(self._kept)
        if len(kept) < 3:
            return np.inf
        recent = [k for k in kept if k[0] >= kept[-1][0] - START_SPAN]
        recent = kept[-3:] if len(recent) < 3 else recent
        slope, _ = fitted_velocity(np.array([k[0] for k in recent]), np.array([k[1] for k in recent]))
        return float(np.linalg.norm(slope))

    def _resting(self, samples) -> np.ndarray | None:
        """Where the hand rests over the last window of ``samples`` ((t, position, velocity) ...), or None."""
        s = self.settings
        newest = samples[-1]
        oldest = next(k for k in samples if k[0] >= newest[0] - s.window)   # the window's first sample
        if too_far_apart_to_rest(oldest[1], newest[1], s.radius):          # a moving hand's every sample: no arrays
            return None
        return resting_position(np.array([k[0] for k in samples]), np.array([k[1] for k in samples]), s.window, s.radius,
                                creep=s.creep)
