"""Goal estimates over an uninterrupted stream of a hand: rest, reach, rest, the next reach, with no reset.

:class:`ReachStream` runs an :class:`~comanip.estimation.streaming.estimation_loop.EstimationLoop` over samples that come
paired (time s, position m, velocity m/s) and estimates every sample of a reach at once: the reaches are found
in the motion itself (:mod:`comanip.estimation.streaming.reach_segmentation`), each starts the stream's
:class:`~comanip.estimation.online.online_estimator.OnlineGoalEstimator` anew (``reset``) and feeds it the reach's
samples, from the rest just before the hand left it; its estimates are the stream's, numbered by the reach. The
estimator holds only the reach's own samples, so the cost of an update is bounded by the longest reach, not by
the length of the stream. What it learns of the person (:attr:`ReachStream.person`,
:mod:`comanip.estimation.calibration.person_calibration`) carries over: each reach is learned from when the hand rests
again, and :meth:`ReachStream.forget_person` starts over with a new person.
"""

from __future__ import annotations

from dataclasses import dataclass


from comanip.estimation.calibration.person_calibration import PersonCalibration
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.model_reaches.model_families import FamilyCache
from comanip.estimation.online.online_estimator import OnlineGoalEstimator
from comanip.estimation.streaming import online_settings
from comanip.estimation.streaming.estimation_loop import LoopEvent
from comanip.estimation.streaming.online_settings import OnlineSettings


@dataclass(frozen=True)
class StreamEstimate:
    """What :meth:`ReachStream.update` knows after a sample."""

    reach: int
    """Reaches started so far (0 before the first); the estimate is the latest reach's."""
    moving: bool
    """True while a reach is under way; False at rest (before the first reach, or after one ended)."""
    estimate: OnlineEstimate | None
    """The latest reach's latest estimate (its plan, goal and covariance); None before the first reach."""
    reach_start: float | None
    """Stream time (s) at which the latest reach's estimator clock starts (its ``time_s`` 0); None before it."""


class ReachStream:
    """Goal estimates over a stream of successive reaches (module docstring).

    Args:
        model: a ReachingModel or Planner of a point mass, as :class:`OnlineGoalEstimator` takes it; None: the one
            ``settings`` names.
        settings: the online estimation (:class:`~comanip.estimation.streaming.online_settings.OnlineSettings`, or
            the name or YAML path of one, :func:`~comanip.estimation.streaming.online_settings.load`); default
            ``recorded``, a person who may not move as the model does.
        prior_goal: g_bar (d,) m of every reach; None: each reach's start.
        cache: where the reach family is kept (the process's when None).
        person: what is known of the person (:class:`~comanip.estimation.calibration.person_calibration.PersonCalibration`);
            None: a person not seen yet.

    The model's reach family is built here (a second or so, once per model and width, kept in the cache), so
    that the first reach of the stream starts as fast as the others; bad settings are refused here too.
    """

    def __init__(self, model=None, settings: OnlineSettings | str = "recorded", *, prior_goal=None,
                 cache: FamilyCache | None = None, person: PersonCalibration | None = None):
        self.settings = online_settings.load(settings)
        self.loop = self.settings.estimation_loop(prior_goal=prior_goal, model=model, cache=cache, person=person)
        """The stream's loop: its reaches, segmenter and estimator."""
        self.model = self.loop.estimator.model if model is None else model
        self.person = self.loop.estimator.person
        """What the stream's reaches have taught of the person."""
        self.reset()

    def reset(self) -> None:
        """Start over: at rest, no reach (never needed: a rest ends every reach)."""
        self.loop.restart()
        self.latest = StreamEstimate(0, False, None, None)

    def forget_person(self) -> None:
        """Forget what was learned of the person: the next reaches are a new person's."""
        self.person.forget()

    @property
    def estimator(self) -> OnlineGoalEstimator | None:
        """The estimator of the reach under way; None at rest."""
        return self.loop.estimator if self.loop.under_way else None

    def update(self, time_s: float, position, velocity) -> StreamEstimate:
        """Add a sample (stream time s, increasing; position (d,) m; velocity (d,) m/s) and return what is known.

        A sample the tracker lost (all NaN) is skipped, as :meth:`OnlineGoalEstimator.update` skips it."""
        if self.loop.add_sample(time_s, position, velocity).event is LoopEvent.LOST:
            return self.latest
        update = self.loop.take_due()
        estimate = self.latest.estimate if update is None else self.loop.estimate(update)
        reach = self.loop.reach
        self.latest = (StreamEstimate(0, False, None, None) if reach is None
                       else StreamEstimate(reach.number, self.loop.moving, estimate, reach.clock))
        return self.latest
