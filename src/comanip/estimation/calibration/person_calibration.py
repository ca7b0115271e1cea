"""What the online estimator learns of one person from their finished reaches.

Explanations are fitted to other people (or to the model). A person moves their own way: they may stop
consistently farther or shorter than the estimate says, end their reaches sooner or later, and be harder to
predict than the people the estimates were fitted on. Once a reach is over, its endpoint and when the hand
stopped are known, so each of its estimates can be scored. :class:`PersonCalibration` keeps three factors of
one person, each the geometric mean of what their finished reaches show, shrunk towards the factor for a
person not seen yet with the weight of ``prior_reaches`` reaches:

- **amplitude** a: how far beyond the hand the endpoint lay, along what each estimate said was still to go,
  over that (the median over a reach's estimates from 25 % to 90 % of its movement time); the estimate's
  goal becomes x + a (g - x), x the hand, so a hand that has stopped keeps its goal;
- **pace** p: the time the hand still moved after each estimate over the time the estimate gave it (the
  median, over those that gave one); the estimate's stop becomes t + p (t_stop - t);
- **spread** c: the factor on the goal's covariance (amplitude applied) that makes its 95 % region hold the
  endpoint at 95 % of the estimates of the person's last ``REMEMBERED`` reaches (the 95th percentile of their
  squared Mahalanobis distances over the chi² 95 % quantile, at the person's amplitude); the covariance
  becomes c a² P. A person not seen yet gets ``new_person_spread``;
- **forecast spread** c_f: the same for the forecast of the hand at :data:`FORECAST_LEADS` after each estimate
  (its covariance at those times against where the hand was); the forecast's covariance becomes c_f times its
  own. A person not seen yet gets 1.

A reach is learned from when it is over (:meth:`PersonCalibration.learn`): the online estimator does it in
``reset()`` when the hand had come to rest away from its start, and :meth:`PersonCalibration.forget` starts
over with a new person.

Shapes: d task dimensions, K estimates.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from comanip.arguments import as_nonnegative, as_positive

SCORED_SPAN = (0.25, 0.9)
"""The part of a finished reach whose estimates are scored (fractions of its movement time from the onset)."""
NEW_PERSON_SPREAD = 1.0
"""The spread of a person not seen yet: the factor on the goal's covariance."""
FACTOR_RANGE = (0.2, 5.0)
"""A reach's amplitude and pace factors are clipped to this range (a reach they say more of is another task)."""
SPREAD_RANGE = (0.01, 1e4)
"""The spread factor stays in this range (exact observations of a reach would drive it to zero)."""
FORECAST_LEADS = (0.1, 0.2, 0.3)
"""Leads (s) after an estimate at which its forecast of the hand is scored."""
REMEMBERED = 20
"""The spread is read from the estimates of the person's last this many finished reaches."""


@dataclass(frozen=True)
class CalibrationSettings:
    """How :class:`PersonCalibration` learns (module docstring)."""

    prior_reaches: float = 1.0
    """Weight, in reaches, of the factors of a person not seen yet against what the person's reaches show."""
    new_person_spread: float = NEW_PERSON_SPREAD
    """The spread factor of a person not seen yet (on the goal's covariance)."""
    learns: bool = True
    """False: nothing is learned, every reach is a person not seen yet's (calibration off)."""

    def __post_init__(self):
        if not isinstance(self.learns, bool):
            raise ValueError(f"learns must be True or False, got {self.learns!r}")
        as_nonnegative("prior_reaches", self.prior_reaches, "reaches")
        as_positive("new_person_spread", self.new_person_spread, "factor on the goal's covariance")


@dataclass(frozen=True)
class FinishedReach:
    """One finished reach and the estimates made during it (before calibration)."""

    start: np.ndarray
    """Where it started (d,), m."""
    end: np.ndarray
    """Where the hand came to rest (d,), m."""
    onset_s: float
    """When the hand set off (s, the estimator's clock)."""
    end_s: float
    """When it stopped (s)."""
    t: np.ndarray
    """Times of the estimates (K,), s."""
    hands: np.ndarray
    """Where the hand was at each (K, d), m."""
    goals: np.ndarray
    """Their goals (K, d), m."""
    covariances: np.ndarray
    """Their goals' covariances (K, d, d), m²."""
    stops: np.ndarray
    """The stop times they gave (K,), s; NaN where none."""
    forecasts: np.ndarray
    """Their forecasts' positions at t + :data:`FORECAST_LEADS` (K, L, d), m."""
    forecast_covariances: np.ndarray
    """And those positions' covariances (K, L, d, d), m²."""
    hand_t: np.ndarray
    """Times of the hand's observations (M,), s."""
    hand_position: np.ndarray
    """The hand's positions (M, d), m: where the forecasts are scored (held at the last after it)."""


@dataclass(frozen=True)
class ReachFactors:
    """What one finished reach shows (module docstring); None where it shows nothing."""

    amplitude: float | None
    pace: float | None


@dataclass(frozen=True)
class ScoredEstimates:
    """A finished reach's estimates from 25 % to 90 % of its movement time, scored against its endpoint."""

    offsets: np.ndarray
    """Goals minus the hand (K, d), m: what the estimates said was still to go."""
    covariances: np.ndarray
    """Their covariances (K, d, d), m²."""
    ends: np.ndarray
    """The endpoint minus the hand (K, d), m: what was still to go."""
    forecast_distances: np.ndarray
    """The forecasts' squared Mahalanobis distances to where the hand was at the leads (K·L,)."""

    def spread(self, amplitude: float) -> np.ndarray:
        """The estimates' squared Mahalanobis distances to the endpoint (K,), what they said was still to go and
        their covariances scaled by ``amplitude``."""
        errors = self.ends - amplitude * self.offsets
        return np.einsum("ki,ki->k", errors, np.linalg.solve(amplitude**2 * self.covariances, errors[:, :, None])[:, :, 0])


def scored_span(reach: FinishedReach) -> np.ndarray:
    """Which of the reach's estimates (K,) lie from 25 % to 90 % of its movement time (:data:`SCORED_SPAN`)."""
    duration = reach.end_s - reach.onset_s
    return (reach.t >= reach.onset_s + SCORED_SPAN[0] * duration) & (reach.t <= reach.onset_s + SCORED_SPAN[1] * duration)


def scored_estimates(reach: FinishedReach) -> ScoredEstimates | None:
    """The estimates of ``reach`` its factors are read from (those of :func:`scored_span` with a goal away from the
    hand), or None."""
    offsets = reach.goals - reach.hands
    scored = scored_span(reach) & (np.linalg.norm(offsets, axis=1) > 1e-6)
    if reach.end_s <= reach.onset_s or not scored.any():
        return None
    times = reach.t[scored, None] + np.array(FORECAST_LEADS)
    truth = np.stack([np.interp(times, reach.hand_t, column) for column in reach.hand_position.T], axis=-1)
    errors = (reach.forecasts[scored] - truth).reshape(-1, reach.end.size)
    covariances = reach.forecast_covariances[scored].reshape(-1, reach.end.size, reach.end.size)
    try:
        distances = np.einsum("ki,ki->k", errors, np.linalg.solve(covariances, errors[:, :, None])[:, :, 0])
    except np.linalg.LinAlgError:
        distances = np.zeros(0)
    return ScoredEstimates(offsets[scored], reach.covariances[scored], reach.end - reach.hands[scored], distances)


def reach_factors(reach: FinishedReach, scored: ScoredEstimates | None = None) -> ReachFactors:
    """The amplitude and pace factors (module docstring) one finished reach shows (``scored``: its
    :func:`scored_estimates`, when already at hand)."""
    scored = scored or scored_estimates(reach)
    if scored is None:
        return ReachFactors(None, None)
    lengths = np.linalg.norm(scored.offsets, axis=1)
    along = np.einsum("ki,ki->k", scored.offsets, scored.ends)
    amplitude = float(np.clip(np.median(along / lengths**2), *FACTOR_RANGE))
    within = scored_span(reach)
    left = reach.stops[within] - reach.t[within]
    timed = np.isfinite(left) & (left > 0.02)
    pace = None
    if timed.any():
        pace = float(np.clip(np.median((reach.end_s - reach.t[within][timed]) / left[timed]), *FACTOR_RANGE))
    return ReachFactors(amplitude, pace)


class PersonCalibration:
    """The amplitude, pace and spread factors of one person (module docstring), learned from their reaches."""

    def __init__(self, settings: CalibrationSettings | None = None):
        self.settings = settings or CalibrationSettings()
        if not isinstance(self.settings, CalibrationSettings):
            raise ValueError(f"settings must be a CalibrationSettings, got {type(self.settings).__name__}")
        self.forget()

    def forget(self) -> None:
        """Start over with a person not seen yet."""
        self._amplitudes: list[float] = []          # logs
        self._paces: list[float] = []               # logs
        self._scored: list[ScoredEstimates] = []    # the last REMEMBERED reaches
        self.spread = self.settings.new_person_spread
        """The factor on the goal's covariance (besides the amplitude's square)."""
        self.forecast_spread = 1.0
        """The factor on the forecast's covariance."""

    @property
    def reaches(self) -> int:
        """Finished reaches learned from."""
        return len(self._amplitudes)

    def _shrunk(self, logs: list[float], new_person: float) -> float:
        weight = self.settings.prior_reaches
        if not logs:
            return new_person
        return math.exp((weight * math.log(new_person) + sum(logs)) / (weight + len(logs)))

    @property
    def amplitude(self) -> float:
        """The factor on the goal's distance from the start."""
        return self._shrunk(self._amplitudes, 1.0)

    @property
    def pace(self) -> float:
        """The factor on the time the hand still moves."""
        return self._shrunk(self._paces, 1.0)

    def learn(self, reach: FinishedReach) -> ReachFactors:
        """Learn from a finished reach; returns what it showed. The spread is read again from the person's last
        :data:`REMEMBERED` reaches at the amplitude learned now."""
        scored = scored_estimates(reach)
        shown = reach_factors(reach, scored)
        if shown.amplitude is None or not self.settings.learns:
            return shown
        self._amplitudes.append(math.log(shown.amplitude))
        if shown.pace is not None:
            self._paces.append(math.log(shown.pace))
        self._scored = [*self._scored, scored][-REMEMBERED:]
        try:
            self.spread = self._pooled([scored.spread(self.amplitude) for scored in self._scored],
                                       self.settings.new_person_spread, len(reach.end), self.spread)
        except np.linalg.LinAlgError:
            pass
        self.forecast_spread = self._pooled([scored.forecast_distances for scored in self._scored], 1.0, len(reach.end),
                                            self.forecast_spread)
        return shown

    def _pooled(self, distances: list[np.ndarray], new_person: float, d: int, before: float) -> float:
        """The factor that makes 95 % regions hold 95 % of the pooled squared Mahalanobis ``distances`` (d-dimensional),
        within :data:`SPREAD_RANGE` and shrunk towards ``new_person``; ``before`` where there are none."""
        pooled = np.concatenate(distances)
        if not pooled.size:
            return before
        seen = float(np.percentile(pooled, 95) / chi2.ppf(0.95, d))
        if not math.isfinite(seen):
            return before
        seen, weight = min(max(seen, SPREAD_RANGE[0]), SPREAD_RANGE[1]), self.settings.prior_reaches
        return math.exp((weight * math.log(new_person) + self.reaches * math.log(seen)) / (weight + self.reaches))

    def goal(self, hand: np.ndarray, goal: np.ndarray, covariance: np.ndarray,
             axes: Sequence[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(goal (d,) m, covariance (d, d) m²) of an estimate for this person, the hand at ``hand`` (d,) m.

        ``axes``: the axes the person leads (what they were learned from); the others are left as they are.
        None: every axis."""
        a, factor = self.amplitude, self.spread * self.amplitude**2
        if a != 1.0:
            axes = list(range(goal.size)) if axes is None else list(axes)
            goal = goal.copy()
            goal[axes] = hand[axes] + a * (goal[axes] - hand[axes])
        return goal, scaled_on_axes(covariance, factor, axes)

    def stop(self, t_now: float, stop_s: float) -> float:
        """The stop time (s) of an estimate made at ``t_now`` (s) that said ``stop_s`` (s)."""
        pace = self.pace
        return stop_s if pace == 1.0 else t_now + pace * max(stop_s - t_now, 0.0)


def scaled_on_axes(covariance: np.ndarray, factor: float, axes: Sequence[int] | None) -> np.ndarray:
    """``covariance`` (..., d, d) with its variances along ``axes`` times ``factor`` and their covariances with the
    other axes times √factor (D P D, D diagonal: √factor on ``axes``, 1 elsewhere; positive semidefinite as P is).
    None: every axis (factor · P)."""
    if factor == 1.0:
        return covariance
    if axes is None:
        return factor * covariance
    scale = np.ones(covariance.shape[-1])
    scale[list(axes)] = math.sqrt(factor)
    return covariance * scale[:, None] * scale[None, :]
