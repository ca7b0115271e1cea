"""Online goal estimates of recorded trials in one call: each recording streamed through the loop of an
online estimation (:mod:`comanip.estimation.streaming.online_settings`) as a live tracker would deliver it.

Each :class:`~comanip.recordings.Recording` is one reach, at rest at its first sample (the estimator's start), its
times counted from that sample, and every sample is an update (exactly the estimates of streaming it by hand); one
estimator per recording (a person not seen yet), the model's reach family built once for all.
"""

from __future__ import annotations

from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.model_reaches.model_families import FamilyCache
from comanip.estimation.streaming import online_settings
from comanip.estimation.streaming.estimation_loop import LoopSettings
from comanip.estimation.streaming.online_settings import OnlineSettings


def estimate_recordings(model, recordings, settings: OnlineSettings | str = "recorded", *, prior_goal=None,
                        cache: FamilyCache | None = None) -> list[list[OnlineEstimate]]:
    """The estimate after every sample of every recording (module docstring).

    Args:
        model: a ReachingModel or Planner of a point mass whose task space is the recordings' (d); None: the one
            ``settings`` names.
        recordings: :class:`~comanip.recordings.Recording` s (times s, positions (K, d) m, velocities (K, d) m/s).
        settings: the online estimation (an :class:`~comanip.estimation.streaming.online_settings.OnlineSettings`,
            or the name or YAML path of one); its loop's segmentation and rate are not used (every sample is an
            update of the one reach).
        prior_goal: g_bar (d,) m; None: each recording's start.
        cache: where the reach family is kept (one is made for the call when None).

    Returns:
        For each recording, its K estimates in sample order.
    """
    settings = online_settings.load(settings)
    settings = settings.replace(loop=LoopSettings(segmentation=None))
    cache = cache or FamilyCache(size=1)
    results = []
    for recording in recordings:
        loop = settings.estimation_loop(prior_goal=prior_goal, model=model, cache=cache)
        loop.begin(float(recording.t[0]), recording.position[0])
        estimates = []
        for t, p, v in zip(recording.t, recording.position, recording.velocity):
            loop.add_sample(float(t), p, v)
            update = loop.take_due()
            if update is not None:
                estimates.append(loop.estimate(update))
        results.append(estimates)
    return results
