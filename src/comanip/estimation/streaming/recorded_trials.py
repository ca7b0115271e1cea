"""Online goal estimates of recorded trials in one call: each recording streamed to an
:class:`~comanip.estimation.online.online_estimator.OnlineGoalEstimator` as a live tracker would deliver it.

Each :class:`~comanip.recordings.Recording` is fed sample by sample from its first, its times counted from that
sample, the hand at rest there; the estimates are exactly those of streaming it by hand (one estimator per
recording, the model's reach family built once for all).
"""

from __future__ import annotations

import numpy as np

from comanip.estimation.goal_estimate import GoalEstimate
from comanip.estimation.model_reaches.model_families import FamilyCache
from comanip.estimation.online.online_estimator import OnlineGoalEstimator


def estimate_recordings(model, recordings, *, cache: FamilyCache | None = None, **estimator_options) -> list[list[GoalEstimate]]:
    """The estimate after every sample of every recording (module docstring).

    Args:
        model: a ReachingModel or Planner of a point mass whose task space is the recordings' (d).
        recordings: :class:`~comanip.recordings.Recording` s (times s, positions (K, d) m, velocities (K, d) m/s).
        cache: where the reach family is kept (one is made for the call when None).
        estimator_options: keyword arguments of :class:`OnlineGoalEstimator` (``prior_goal``, ``prior_std``,
            ``width``, ``options``).

    Returns:
        For each recording, its K estimates in sample order.
    """
    cache = cache or FamilyCache(size=1)
    nx = (getattr(model, "model", model)).state_size
    results = []
    for recording in recordings:
        start = np.r_[recording.position[0], np.zeros(nx - recording.position.shape[1])]
        estimator = OnlineGoalEstimator(model, start, cache=cache, **estimator_options)
        t0 = float(recording.t[0])
        results.append([estimator.update(float(t) - t0, p, v)
                        for t, p, v in zip(recording.t, recording.position, recording.velocity)])
    return results
