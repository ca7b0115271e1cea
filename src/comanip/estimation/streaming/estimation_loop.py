"""The loop that feeds a hand tracker's stream to one goal estimator, written once for every front end.

A tracker delivers the hand's positions (d,) m and velocities (d,) m/s, stamped in s, either as separate
samples (a ROS node's pose and twist) or already paired; a person reaches, rests and reaches again, with no
reset. :class:`EstimationLoop` decides for each position, cheaply enough for every sample, what it is for, and
says so in a :class:`LoopStep` (its :class:`LoopEvent`):

1. **Pairing.** A position waits (``WAITING``) for the velocity stamped nearest it, within
   ``LoopSettings.pairing_tolerance``; one older than the newest velocity by more than that will never be paired
   (velocities arrive in stamp order) and is not used (``UNPAIRED``). A sample the tracker lost (all NaN) is
   skipped (``LOST``).
2. **Segmentation** (:class:`~comanip.estimation.streaming.reach_segmentation.ReachSegmenter`, every paired sample). A
   reach starts (``STARTED``) where the hand leaves its rest: at rest there, its clock (t = 0) at the start of
   the segmenter's ``lead`` before it, whose samples it begins with. With ``first_sample_starts_reach`` the
   first sample (after construction, :meth:`EstimationLoop.restart`, or a gap longer than ``restart_after``)
   starts one instead, at rest where it is, its clock at its stamp; the hand's first departure from that rest
   belongs to it (unless it comes past the reach's ``horizon``: then it starts the next). A reach finishes (``FINISHED``) when the hand rests again; until the next reach starts, the
   samples are only segmented (``AT_REST``). Without segmentation (``LoopSettings.segmentation`` None: a
   stream that is one reach, such as a simulated trial) the first sample starts the reach as with
   ``first_sample_starts_reach`` (or :meth:`EstimationLoop.begin` starts it where the front end knows its clock
   and start) and every later one belongs to it.
3. **Due times.** Within a reach, ``rate`` updates per second of stream time are due (``DUE``), on a grid of
   1 / rate from the reach's clock: the sample nearest each due time (the first within half the sample spacing
   of it) is due, so a tracker whose stamps jitter still gets the rate (a rule of 'one period since the last
   update' loses up to a sample spacing every period); after a gap longer than a period the grid restarts at
   the next sample. The others are skipped (``NOT_DUE``); a sample ``horizon`` s or more after the reach's clock
   is not used (``PAST_HORIZON``). The sample that starts a reach from the segmenter and the one that finishes
   a reach are always due.
4. **The newest first.** A due sample becomes the loop's :class:`Update` (:attr:`EstimationLoop.due`), replacing
   one not yet taken (counted in :attr:`EstimationLoop.replaced`): an estimate runs on the newest sample, never
   on a stale one, however long the one before took.
5. **Estimation** (:meth:`EstimationLoop.estimate`, which may run on another thread than steps 1-4, one update
   at a time). The first update of a reach restarts the estimator (``reset`` from the reach's rest, with the
   prior goal the reach started with; the reach before is learned from) and gives it the reach's lead samples
   (their estimates unread: :meth:`~comanip.estimation.online.online_estimator.OnlineGoalEstimator.observe`); then the sample, at t = stamp - the reach's clock; an update that finishes its reach then has the
   estimator learn from it (``finish_reach``).

What each front end adds is its own: :class:`~comanip.estimation.streaming.reach_stream.ReachStream` estimates every due
update at once; the ROS 2 node (:mod:`comanip.ros.node`) converts messages into samples, estimates once the
messages that have arrived are read, and publishes.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from comanip.arguments import as_nonnegative, as_positive
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.hand_rest import lost_sample
from comanip.estimation.online.online_estimator import OnlineGoalEstimator
from comanip.estimation.streaming.reach_segmentation import ReachSegmenter, SegmentationSettings

PAIRING_DEPTH = 50
"""Most velocities kept for pairing, and most positions waiting for theirs (a longer wait is ``UNPAIRED``)."""


class LoopEvent(Enum):
    """What a position was for (module docstring, steps 1-4)."""

    WAITING = "waiting for its velocity"
    UNPAIRED = "no velocity within the pairing tolerance: not used"
    LOST = "lost by the tracker: skipped"
    AT_REST = "the hand rests between reaches: segmented only"
    STARTED = "started a reach"
    DUE = "an update is due"
    NOT_DUE = "between due times: skipped"
    PAST_HORIZON = "past the horizon of its reach: not used"
    FINISHED = "the hand rests: its reach is over, its last update is due"


@dataclass(frozen=True)
class LoopSettings:
    """How the loop pairs, segments and paces a stream (module docstring)."""

    segmentation: SegmentationSettings | None = field(default_factory=SegmentationSettings)
    """Rests and reaches (:class:`~comanip.estimation.streaming.reach_segmentation.SegmentationSettings`); None: the
    stream is one reach, from its first sample (module docstring, step 2)."""
    rate: float | None = None
    """Most updates per second of stream time (Hz); None: every sample of a reach."""
    pairing_tolerance: float = 0.005
    """Largest stamp difference (s) between a position and the velocity paired with it."""
    horizon: float = math.inf
    """Samples this long (s) or longer after their reach's clock are not used (the model's horizon H·h)."""
    restart_after: float | None = None
    """A gap between two positions longer than this (s) ends the reach under way and starts the segmentation over
    (with ``first_sample_starts_reach``, the sample after the gap starts the next reach); None: never."""
    first_sample_starts_reach: bool = False
    """True: the first sample starts a reach (module docstring, step 2); False: only the hand leaving its rest."""

    def __post_init__(self):
        if self.segmentation is not None and not isinstance(self.segmentation, SegmentationSettings):
            raise ValueError(f"segmentation must be a SegmentationSettings or None, got {type(self.segmentation).__name__}")
        if self.rate is not None:
            as_positive("rate", self.rate, "Hz")
        as_nonnegative("pairing_tolerance", self.pairing_tolerance, "s")
        if not self.horizon > 0:
            raise ValueError(f"horizon must be > 0 (s), got {self.horizon!r}")
        if self.restart_after is not None:
            as_positive("restart_after", self.restart_after, "s")


@dataclass(frozen=True, eq=False)
class HandSample:
    """The hand at one stamp."""

    stamp: float
    """Stream time (s)."""
    position: np.ndarray
    """(d,) m."""
    velocity: np.ndarray
    """(d,) m/s."""
    received: float = math.nan
    """When the position arrived (``time.perf_counter()``, s), for a front end's latency; NaN: not told."""


@dataclass(frozen=True, eq=False)
class Reach:
    """A reach the loop has started (one object per reach: the loop tells reaches apart by identity)."""

    number: int
    """Reaches started since the loop (re)started, this one included (1 for the first)."""
    clock: float
    """Stream time (s) of the reach's t = 0."""
    start: np.ndarray
    """Where the hand rests when it starts (d,) m: its estimator's start, at rest."""
    prior_goal: np.ndarray | None
    """The prior goal (d,) m its estimator gets; None: the start."""
    lead: tuple[HandSample, ...]
    """Its samples from its clock up to the one that started it, which its estimator gets first."""


@dataclass(frozen=True, eq=False)
class Update:
    """An estimator update the loop has made due (module docstring, step 5)."""

    reach: Reach
    sample: HandSample | None
    """The observation; None: the update only finishes its reach (its last sample lay past the horizon)."""
    finishes: bool
    """True: the estimator learns from the reach after this update (its hand rests)."""

    @property
    def t(self) -> float:
        """The observation's time since its reach's clock (s); NaN without one."""
        return math.nan if self.sample is None else self.sample.stamp - self.reach.clock


@dataclass(frozen=True)
class LoopStep:
    """What one position was for."""

    event: LoopEvent
    stamp: float
    """The position's stamp (s)."""
    update: Update | None = None
    """The update it made due (until taken, :attr:`EstimationLoop.due`); None when it made none."""


class EstimationLoop:
    """Pairing, segmentation, due times and restarts of one estimator over a stream (module docstring).

    Args:
        estimator: the :class:`~comanip.estimation.online.online_estimator.OnlineGoalEstimator` the loop restarts for every
            reach (what it learns of the person carries over).
        settings: :class:`LoopSettings`.
    """

    def __init__(self, estimator: OnlineGoalEstimator, settings: LoopSettings | None = None):
        self.estimator = estimator
        self.settings = settings or LoopSettings()
        if not isinstance(self.settings, LoopSettings):
            raise ValueError(f"settings must be a LoopSettings, got {type(self.settings).__name__}")
        segmentation = self.settings.segmentation
        self.segmenter = None if segmentation is None else ReachSegmenter(segmentation)
        """The segmenter of the stream's reaches; None without segmentation."""
        self.prior_goal: np.ndarray | None = estimator.prior_goal
        """The prior goal (d,) m of the reaches started from now on; None: each reach's start."""
        self.replaced = 0
        """Due updates replaced by a newer one before they were taken (module docstring, step 4)."""
        self._estimated: Reach | None = None          # the reach the estimator holds (step 5's side)
        self.restart()

    def restart(self) -> None:
        """Start over: no reach, nothing waiting or due (what the estimator knows of the person stays)."""
        if self.segmenter is not None:
            self.segmenter.reset()
        self._velocities: deque = deque(maxlen=PAIRING_DEPTH)    # (stamp, velocity), in stamp order
        self._waiting: list[tuple[float, np.ndarray, float | None, float]] = []   # (stamp, position, previous stamp, received)
        self._previous: float | None = None           # stamp of the latest position
        self._next_due = -math.inf
        self.reach: Reach | None = None
        """The latest reach (it stays after it finishes); None before the first."""
        self.under_way = False
        """True from a reach's start until it finishes."""
        self.due: Update | None = None
        """The update due and not yet taken (:meth:`take_due`)."""

    def begin(self, clock: float, start) -> Reach:
        """Start a reach at stream time ``clock`` (s), at rest at ``start`` (d,) m, where a front end knows when and
        where its stream's reach starts (a simulated trial): without segmentation, every later sample is its own
        (module docstring, step 2) and the due times count from ``clock``."""
        start = np.array(start, dtype=float)
        self._start(Reach(1 if self.reach is None else self.reach.number + 1, float(clock), start, self.prior_goal, ()))
        return self.reach

    @property
    def moving(self) -> bool:
        """True while the hand moves (the segmenter has found it leaving its rest and not yet resting again; without
        segmentation, while the stream's reach is under way)."""
        return self.under_way if self.segmenter is None else self.segmenter.moving

    @property
    def waiting(self) -> int:
        """Positions waiting for their velocities."""
        return len(self._waiting)

    # ---- steps 1-4: every sample, cheap
    def add_sample(self, stamp: float, position, velocity, received: float = math.nan) -> LoopStep:
        """A paired sample: stamp (s, after the previous one's), position (d,) m, velocity (d,) m/s."""
        stamp = float(stamp)
        if self._previous is not None and not stamp > self._previous:
            raise ValueError(f"time_s must increase from sample to sample: got {stamp:g} s after {self._previous:g} s")
        if lost_sample(position) or lost_sample(velocity):
            return LoopStep(LoopEvent.LOST, stamp)
        previous, self._previous = self._previous, stamp
        return self._observe(HandSample(stamp, np.asarray(position, dtype=float), np.asarray(velocity, dtype=float), received),
                             previous)

    def add_position(self, stamp: float, position, received: float = math.nan) -> list[LoopStep]:
        """A position (d,) m stamped ``stamp`` (s, after the previous position's) that waits for its velocity: the
        steps of every position decided now (this one ``WAITING`` if it still waits)."""
        self._waiting.append((float(stamp), np.asarray(position, dtype=float), self._previous, received))
        self._previous = float(stamp)
        steps = self._pair()
        if self._waiting and self._waiting[-1][0] == stamp:
            steps.append(LoopStep(LoopEvent.WAITING, float(stamp)))
        return steps

    def add_velocity(self, stamp: float, velocity) -> list[LoopStep]:
        """A velocity (d,) m/s stamped ``stamp`` (s, after the previous velocity's): the steps of the positions it
        decides."""
        self._velocities.append((float(stamp), np.asarray(velocity, dtype=float)))
        return self._pair()

    def _pair(self) -> list[LoopStep]:
        """Each waiting position paired with the velocity stamped nearest it, observed in stamp order (step 1)."""
        tolerance = self.settings.pairing_tolerance + 1e-9
        newest = self._velocities[-1][0] if self._velocities else -math.inf
        steps, waiting = [], []
        for stamp, position, previous, received in self._waiting:
            nearest = min(self._velocities, key=lambda v: abs(v[0] - stamp)) if self._velocities else None
            if nearest is not None and abs(nearest[0] - stamp) <= tolerance:
                steps.append(self._observe(HandSample(stamp, position, nearest[1], received), previous))
            elif stamp < newest - tolerance or len(self._waiting) > PAIRING_DEPTH:
                steps.append(LoopStep(LoopEvent.UNPAIRED, stamp))
            else:
                waiting.append((stamp, position, previous, received))
        self._waiting = waiting
        return steps

    def _observe(self, sample: HandSample, previous: float | None) -> LoopStep:
        """Segment a paired sample, start or finish a reach, and make an update due (steps 2-4); ``previous``: the
        stamp of the position before (s)."""
        s = self.settings
        gap = previous is not None and s.restart_after is not None and sample.stamp - previous > s.restart_after
        if gap:
            if self.segmenter is not None:
                self.segmenter.reset()
            self.under_way = False
        if (s.first_sample_starts_reach or self.segmenter is None) and (self.reach is None or gap):
            if self.segmenter is not None:
                self.segmenter.update(sample.stamp, sample.position, sample.velocity)
            self._start(Reach(1 if self.reach is None else self.reach.number + 1, sample.stamp, sample.position.copy(),
                              self.prior_goal, ()))
            return LoopStep(LoopEvent.STARTED, sample.stamp)
        within = self.reach is not None and sample.stamp - self.reach.clock < s.horizon
        if self.segmenter is None:
            return self._pace(sample, previous, within)
        was_moving = self.segmenter.moving
        started = self.segmenter.update(sample.stamp, sample.position, sample.velocity)
        if started is not None and not (s.first_sample_starts_reach and started.number == 1 and within):
            self._start(Reach(1 if self.reach is None else self.reach.number + 1, started.clock, started.start, self.prior_goal,
                              tuple(HandSample(*kept) for kept in started.samples[:-1])))
            self._next_due = self._following_due(sample.stamp)
            return self._make_due(LoopEvent.STARTED, sample.stamp, sample)
        if not self.under_way:
            return LoopStep(LoopEvent.AT_REST, sample.stamp)
        if was_moving and not self.segmenter.moving:
            self.under_way = False
            return self._make_due(LoopEvent.FINISHED, sample.stamp, sample if within else None, finishes=True)
        return self._pace(sample, previous, within)

    def _pace(self, sample: HandSample, previous: float | None, within: bool) -> LoopStep:
        """A sample of the reach under way: past its horizon, between due times, or due (step 3)."""
        s = self.settings
        if not within:
            return LoopStep(LoopEvent.PAST_HORIZON, sample.stamp)
        half_spacing = 0.5 * (sample.stamp - previous) if previous is not None else 0.0
        if s.rate is not None and sample.stamp < self._next_due - half_spacing - 1e-9:   # the next sample is nearer
            return LoopStep(LoopEvent.NOT_DUE, sample.stamp)
        self._next_due = self._following_due(sample.stamp)
        return self._make_due(LoopEvent.DUE, sample.stamp, sample)

    def _start(self, reach: Reach) -> None:
        self.reach, self.under_way = reach, True
        self._next_due = reach.clock + (0.0 if self.settings.rate is None else 1.0 / self.settings.rate)

    def _following_due(self, stamp: float) -> float:
        """The due time after the one a sample at ``stamp`` (s) met: a period on, or a period after the sample
        when it came more than a period late (a gap)."""
        if self.settings.rate is None:
            return -math.inf
        period = 1.0 / self.settings.rate
        return self._next_due + period if stamp < self._next_due + period else stamp + period

    def _make_due(self, event: LoopEvent, stamp: float, sample: HandSample | None, finishes: bool = False) -> LoopStep:
        update = Update(self.reach, sample, finishes)
        if self.due is not None:
            self.replaced += 1
        self.due = update
        return LoopStep(event, stamp, update)

    def take_due(self) -> Update | None:
        """The update due (None: none), no longer due."""
        update, self.due = self.due, None
        return update

    # ---- step 5: the estimator
    def estimate(self, update: Update) -> OnlineEstimate | None:
        """Run ``update`` on the estimator (module docstring, step 5): its latest estimate (None before any)."""
        reach = update.reach
        if self._estimated is not reach:
            model = self.estimator.model
            self.estimator.reset(np.r_[reach.start, np.zeros(model.state_size - len(reach.start))], prior_goal=reach.prior_goal)
            self._estimated = reach
            if reach.lead:                           # their estimates are not read
                self.estimator.observe([sample.stamp - reach.clock for sample in reach.lead],
                                       [sample.position for sample in reach.lead], [sample.velocity for sample in reach.lead])
        if update.sample is not None:
            self.estimator.update(update.t, update.sample.position, update.sample.velocity)
        if update.finishes:
            self.estimator.finish_reach()
        return self.estimator.latest
