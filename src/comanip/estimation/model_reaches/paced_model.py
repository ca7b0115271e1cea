"""The reaching model's mean reach played at the person's own pace and onset.

A person may reach like the model but faster or slower, and start when they like. The model's mean reach to
a goal at distance D from rest, a(tau; D) along the reach (a :class:`~comanip.estimation.model_reaches.reach_family.ReachFamily`
member), has the shape r(phi) = (a(tau; D) - a(tau_on; D)) / (a(tau_end; D) - a(tau_on; D)) over
phi = (tau - tau_on) / (tau_end - tau_on), tau_on the step its speed first reaches 5 % of its peak and tau_end
the step after it last does (an overshoot and its return are inside)
(:class:`~comanip.estimation.model_reaches.reach_profile.ReachProfile`): the model's movement time, not its horizon.
:func:`~comanip.estimation.model_reaches.profile_fit.fit_profile` fits that shape's displacement, duration and onset to the
observed hand, log(pace) ~ N(0, ``PACE_STD``²) a priori, with the shape of the distance fitted before (it changes little with D); the goal is the start
plus the displacement times D / (a(tau_end; D) - a(tau_on; D)), where the model's movement ends relative to
its goal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.estimation.model_reaches.profile_fit import ProfileFit, fit_profile
from comanip.estimation.model_reaches.reach_family import ReachFamily
from comanip.estimation.model_reaches.reach_profile import ReachProfile
from comanip.estimation.model_reaches.reach_timing import ReachTiming, movement_span

PACE_STD = 0.35
"""Standard deviation of log(pace) a priori: people take their own time, within about ×0.5–×2 of the model's."""
GOAL_FLOOR = 0.01
"""Standard deviation added to the goal in every direction, a fraction of its distance: the shape is the
model's at a nearby distance, and a person's reach is never exactly the model's."""
_SHAPE_BINS = 0.05
"""Shapes are kept per bin of this width in log D."""


@dataclass(frozen=True)
class _Shape:
    profile: ReachProfile
    duration: float
    """tau_end - tau_on (s): T at the model's pace."""
    onset: float
    """tau_on (s): t_0 at the model's timing."""
    goal_over_end: float
    """D / (a(tau_end; D) - a(tau_on; D))."""


@dataclass(frozen=True)
class PacedFit:
    """The model's reach fitted at the person's pace (module docstring)."""

    goal: np.ndarray
    """Goal (d,), m."""
    covariance: np.ndarray
    """Its covariance (d, d), m²."""
    pace: float
    """Fitted duration over the model's: > 1 slower than the model, < 1 faster."""
    onset: float
    """Fitted onset (s) of the shape."""
    delay: float
    """Fitted onset minus the model's own (tau_on, for a reach that starts at t = 0), s."""
    duration: float
    """Fitted movement time T (s)."""
    misfit: float
    """chi² per observed number of the fit (:mod:`comanip.estimation.model_reaches.profile_fit`)."""
    observations: int
    """Observations at or after the fitted onset."""

    @property
    def timing(self) -> ReachTiming:
        """The fitted onset and movement time."""
        return ReachTiming(self.onset, self.duration)


class PacedModel:
    """Fits of the model's mean reach at the person's pace, for one reach family (module docstring)."""

    def __init__(self, family: ReachFamily):
        self.family = family
        self._shapes: dict[int, _Shape] = {}

    def shape(self, distance: float) -> _Shape:
        """The shape of the model's reach to ``distance`` (m), from the nearest bin in log D."""
        low, high = self.family.distances[0], self.family.distances[-1]
        key = self._key(distance)
        if key not in self._shapes:
            D = min(max(math.exp(key * _SHAPE_BINS), low), high)
            along = self.family.along(np.array([D]))[0]                 # (H+1, blocks): position, velocity, ...
            h = self.family.model.h
            t = h * np.arange(len(along))
            first, last = movement_span(np.abs(along[:, 1]))
            profile = ReachProfile.from_path(t[first:last + 1], along[first:last + 1, 0], along[first:last + 1, 1],
                                             "the model's reach")
            self._shapes[key] = _Shape(profile, float(t[last] - t[first]), float(t[first]),
                                       D / float(along[last, 0] - along[first, 0]))
        return self._shapes[key]

    def fit(self, t, position, velocity, start, onset: float, distances) -> PacedFit:
        """Fit to observations (times (K,) s, positions (K, d) m, velocities (K, d) m/s) from rest at ``start``
        (d,) m, with the detected ``onset`` (s). The shape is tried at each of the guessed goal ``distances`` (m)
        and then at the best fit's distance; the fit with the smallest misfit wins (a shape taken at a distance
        far from the one it fits can lock into a wrong pace and distance)."""
        best, tried = None, set()
        for distance in list(distances) + [None]:
            if distance is None:                    # refit at the distance the best fit so far found
                distance = min(best[0], 3 * max(distances))
            key = self._key(distance)
            if key in tried:
                continue
            tried.add(key)
            shape = self.shape(distance)
            fit: ProfileFit = fit_profile(t, position, velocity, start, shape.profile, onset,
                                          duration_prior=(shape.duration, PACE_STD))
            found = float(np.linalg.norm(fit.goal - start)) * shape.goal_over_end
            if best is None or fit.misfit < best[1].misfit:
                best = (found, fit, shape)
        _, fit, shape = best
        scale = shape.goal_over_end
        goal = start + scale * (fit.goal - start)
        floor = (GOAL_FLOOR * float(np.linalg.norm(goal - start))) ** 2 * np.eye(len(goal))
        return PacedFit(goal=goal, covariance=scale**2 * fit.covariance + floor, pace=fit.duration / shape.duration,
                        onset=fit.onset, delay=fit.onset - shape.onset, duration=fit.duration, misfit=fit.misfit,
                        observations=int(np.count_nonzero(np.asarray(t) >= fit.onset)))

    def _key(self, distance: float) -> int:
        low, high = self.family.distances[0], self.family.distances[-1]
        return int(round(math.log(min(max(distance, low), high)) / _SHAPE_BINS))
