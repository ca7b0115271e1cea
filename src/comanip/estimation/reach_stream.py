"""Goal estimates over an uninterrupted stream of a hand: rest, reach, rest, the next reach, with no reset.

A robot beside a person sees one stream of hand samples (times s, positions m, velocities m/s) in which the
person makes one reach after another and rests in between. :class:`ReachStream` segments it from the motion
itself (:mod:`comanip.estimation.hand_rest`: rest is judged from positions, which a tracker's noise does not
make move):

1. **At rest.** The last ``lead + window`` seconds of samples are kept. The rest position is where the hand
   rests (the mean of its still positions), or its first sample until it has rested for a window.
2. **A reach starts** when a sample lies farther than ``radius`` from the rest position. A new
   :class:`~comanip.estimation.online_estimator.OnlineGoalEstimator` starts from the rest position at rest,
   its clock at the first kept sample of the last ``lead`` seconds, and is fed those samples and every one
   after them. Its estimates are this object's, numbered by the reach.
3. **The reach ends** when the hand rests again (still for ``window`` seconds after it left the start): the
   estimate of its end stands (its goal is where the hand rests) and the stream is at rest again (1).

Each reach's estimator sees only its own samples, so the cost of an update is bounded by the longest reach,
not by the length of the stream. ``reset()`` starts over at rest (never needed: a rest ends every reach).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_positive
from comanip.estimation.goal_estimate import GoalEstimate
from comanip.estimation.hand_rest import REST_RADIUS_M, REST_WINDOW_S, has_left, resting_position
from comanip.estimation.online_estimator import OnlineGoalEstimator

LEAD_S = 0.15
"""Default time (s) before a reach leaves the rest radius whose samples its estimator sees (the hand at rest,
then its onset)."""


@dataclass(frozen=True)
class SegmentationSettings:
    """How :class:`ReachStream` splits a stream into rests and reaches."""

    radius: float = REST_RADIUS_M
    """A sample farther than this (m) from the rest position starts a reach; a hand whose positions stay
    within it of their mean for ``window`` seconds rests (:mod:`comanip.estimation.hand_rest`)."""
    window: float = REST_WINDOW_S
    """How long (s) the hand must stay still to rest."""
    lead: float = LEAD_S
    """How much of the rest before a reach (s) its estimator sees."""

    def __post_init__(self):
        as_positive("radius", self.radius, "m")
        as_positive("window", self.window, "s")
        as_positive("lead", self.lead, "s")


@dataclass(frozen=True)
class StreamEstimate:
    """What :meth:`ReachStream.update` knows after a sample."""

    reach: int
    """Reaches started so far (0 before the first); the estimate is the latest reach's."""
    moving: bool
    """True while a reach is under way; False at rest (before the first reach, or after one ended)."""
    estimate: GoalEstimate | None
    """The latest reach's latest estimate (its plan, goal and covariance); None before the first reach."""
    reach_start: float | None
    """Stream time (s) at which the latest reach's estimator clock starts (its ``time_s`` 0); None before it."""


class ReachStream:
    """Goal estimates over a stream of successive reaches (module docstring).

    Args:
        model: a ReachingModel or Planner of a point mass, as :class:`OnlineGoalEstimator` takes.
        settings: :class:`SegmentationSettings`.
        estimator_options: keyword arguments for each reach's :class:`OnlineGoalEstimator` (``prior_std``,
            ``width``, ``options``, ``cache``; the start comes from the stream).
    """

    def __init__(self, model, settings: SegmentationSettings | None = None, **estimator_options):
        self.model = model
        self.settings = settings or SegmentationSettings()
        if not isinstance(self.settings, SegmentationSettings):
            raise ValueError(f"settings must be a SegmentationSettings, got {type(self.settings).__name__}")
        self._options = estimator_options
        self.reset()

    def reset(self) -> None:
        """Start over: at rest, no reach, nothing kept."""
        self._kept: deque = deque()              # (t, position, velocity) at rest
        self._reach: OnlineGoalEstimator | None = None
        self._departure = np.inf                 # stream time (s) of the sample that started the reach
        self._reach_samples: list = []           # (t, position, velocity) of the reach under way, to see it end
        self._rest: np.ndarray | None = None
        self._last_time = -np.inf
        self.latest = StreamEstimate(0, False, None, None)

    def update(self, time_s: float, position, velocity) -> StreamEstimate:
        """Add a sample (stream time s, increasing; position (d,) m; velocity (d,) m/s) and return what is known.

        A sample the tracker lost (all NaN) is skipped, as :meth:`OnlineGoalEstimator.update` skips it."""
        time_s = float(time_s)
        if not time_s > self._last_time:
            raise ValueError(f"time_s must increase from sample to sample: got {time_s:g} s after {self._last_time:g} s")
        position, velocity = np.asarray(position, dtype=float), np.asarray(velocity, dtype=float)
        if np.all(np.isnan(position)) or np.all(np.isnan(velocity)):
            return self.latest
        self._last_time = time_s
        if self._reach is None:
            return self._at_rest(time_s, position, velocity)
        return self._in_reach(time_s, position, velocity)

    def _at_rest(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> StreamEstimate:
        s = self.settings
        self._kept.append((time_s, position, velocity))
        while self._kept and self._kept[0][0] < time_s - s.lead - s.window:
            self._kept.popleft()
        if self._rest is None:
            self._rest = position.copy()
        if not has_left(position[None], self._rest, s.radius):
            t = np.array([k[0] for k in self._kept])
            resting = resting_position(t, np.array([k[1] for k in self._kept]), s.window, s.radius)
            if resting is not None:
                self._rest = resting
            return self.latest
        lead = [k for k in self._kept if k[0] >= time_s - s.lead]
        start = np.r_[self._rest, np.zeros(self._state_size() - len(self._rest))]
        self._reach = OnlineGoalEstimator(self.model, start, **self._options)
        begin = lead[0][0]
        self._departure = time_s
        self._reach_samples = []
        self._kept.clear()
        number = self.latest.reach + 1
        for t, p, v in lead:
            estimate = self._reach.update(t - begin, p, v)
            self._reach_samples.append((t, p, v))
        self.latest = StreamEstimate(number, True, estimate, begin)
        return self.latest

    def _in_reach(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> StreamEstimate:
        s, latest = self.settings, self.latest
        estimate = self._reach.update(time_s - latest.reach_start, position, velocity)
        self._reach_samples.append((time_s, position, velocity))
        recent = self._reach_samples[-self._window_samples():]
        resting = None
        if recent[0][0] >= self._departure:     # a rest after the hand left its start, not the rest before it
            resting = resting_position(np.array([k[0] for k in recent]), np.array([k[1] for k in recent]), s.window, s.radius)
        if resting is not None:
            self._reach, self._rest = None, resting
            self._kept = deque(recent)
        self.latest = StreamEstimate(latest.reach, resting is None, estimate, latest.reach_start)
        return self.latest

    @property
    def estimator(self) -> OnlineGoalEstimator | None:
        """The estimator of the reach under way; None at rest."""
        return self._reach

    def _window_samples(self) -> int:
        """How many of the reach's latest samples span the last window, and one more before it."""
        newest, count = self._reach_samples[-1][0], 1
        while count < len(self._reach_samples) and self._reach_samples[-count - 1][0] >= newest - self.settings.window:
            count += 1
        return min(count + 1, len(self._reach_samples))

    def _state_size(self) -> int:
        model = getattr(self.model, "model", self.model)
        return model.state_size
