"""Continuous goal estimation: the goal of a reach in progress, revised with every observation.

A person at rest at s_0 reaches for an unknown goal g; positions and velocities of their hand arrive one at a
time, at any times t_k ≥ 0. After each, :meth:`OnlineGoalEstimator.update` returns an estimate of g, its
covariance and the forecast of where the hand will be (an
:class:`~comanip.estimation.online.online_estimate.OnlineEstimate`), from the model's reach to it played when the
explanation that gives it says the hand moves (:mod:`~comanip.estimation.model_reaches.reach_timing`). The estimate comes from explanations of the hand
(:mod:`comanip.estimation.online.explanations`), asked in order; **the first that explains the hand gives the
estimate** (none: the prior, status ``uninformative``). With ``OnlineOptions(timing="estimated")`` (the default):

1. the hand has not left its start: the prior (:class:`~comanip.estimation.online.explanations.HandAtRest`);
2. the reaching model at its own pace, the reach starting at t = 0: the MAP goal under the model's belief
   (:class:`~comanip.estimation.online.explanations.ModelAtOwnPace`), vetoed for the rest of the reach
   (:class:`~comanip.estimation.online.explanations.Vetoed`) once its misfit exceeds ``OnlineOptions.mismatch_threshold``
   (:class:`~comanip.estimation.online.explanations.MisfitAbove`);
3. the model fitted to recorded people (:class:`~comanip.estimation.online.explanations.RecordedPeople`, status
   ``people_model``).

``timing="paced"`` adds the model's reach at the person's own pace and onset between the second and the third,
where that fits and pins the goal's distance (:class:`~comanip.estimation.online.explanations.ModelAtPersonPace`), and
lets it veto the second where it contradicts the model's timing
(:class:`~comanip.estimation.online.explanations.PaceContradiction`): for hands that move as the model does but at
another pace (a simulated person at ×0.7, say). On recorded people's hands it does not explain the hand, and
it costs more than the rest of an update together, so the default leaves it out.
``timing="model"`` asks only the second, which then always explains the hand (exact for the model's own
reaches). Pass ``explanations=`` to compose your own (each an object with ``reset(reach)`` and
``explain(hand, latest)`` returning an :class:`~comanip.estimation.online.explanations.Explained` with its
:class:`~comanip.estimation.online.explanations.Verdict`: :class:`~comanip.estimation.online.explanations.Explanation`).

The plans come from a :class:`~comanip.estimation.model_reaches.reach_family.ReachFamily` of the model, built once per model
and width: for a rotation-invariant point mass from rest, the plan to any goal is a 1-D reach turned onto its
direction, read from a spline over distance, within ``family.interpolation_error`` (m) of the model's plan. So
an update needs no plan solve.

>>> estimator = OnlineGoalEstimator(comanip.presets.cartesian(), np.zeros(6))
>>> estimate = estimator.update(0.1, position, velocity)
>>> estimate.goal, estimate.goal_covariance, estimate.path.position
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Sequence

import numpy as np

from comanip.arguments import as_vector
from comanip.estimation.model_reaches.estimation_planner import checked_model
from comanip.estimation.online.explanations import (Explained, Explanation, HandAtRest, HandTrace, Reach)
from comanip.estimation.online.explanations.base import grid_position
from comanip.estimation.online.explanations.default_chain import default_explanations
from comanip.estimation.forecast.hand_forecast import ForecastPoint, continued_reach, within_horizon
from comanip.estimation.forecast.path_baselines import recent_acceleration
from comanip.estimation.goal_prior import prior_covariance
from comanip.estimation.calibration.goal_smoothing import GoalSmoother
from comanip.estimation.people.endpoint_baselines import MOVING_SPEED
from comanip.estimation.hand_rest import REST_RADIUS_M, lost_sample, resting_position
from comanip.estimation.model_reaches.model_families import FamilyCache, default_families
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.online.online_options import OnlineOptions
from comanip.estimation.model_reaches.reach_timing import timed_plan
from comanip.estimation.calibration.person_calibration import (FORECAST_LEADS, FinishedReach, PersonCalibration, ReachFactors,
                                                               scaled_on_axes)
from comanip.model import ReachingModel
from comanip.estimation.estimate_status import EstimateStatus
from comanip.plausibility import MAX_HUMAN_HAND_SPEED_M_S, MAX_HUMAN_REACH_M
from comanip.planning.planner import Planner
from comanip.planning.single_thread_blas import SingleThreadBlas
from comanip.units import MAX_REACH_DURATION_S, MAX_REACH_SPAN_M


_SAME = object()
"""reset()'s default prior goal: the one before."""


class OnlineGoalEstimator:
    """Goal estimates of one reach, revised as observations arrive (module docstring).

    Args:
        model: a ReachingModel or Planner of a point mass (activation stages allowed) whose plans are
            rotation-invariant (ValueError otherwise, e.g. for the Panda or per-channel noise).
        start: the state at the reach's start (nx,) or [q; qdot] (2n,), at rest (zero velocity and force).
        prior_goal: g_bar (d,) m; None: the start's hand position (with the weak default std, a prior that
            only keeps the estimate finite).
        prior_std: the prior's standard deviation (m): a number, d numbers, None (the weak default, 10 m)
            or "width" (the paper's W from the width); :mod:`comanip.estimation.goal_prior`.
        width: goal width w (m); the model's default when None.
        options: :class:`~comanip.estimation.online.online_options.OnlineOptions`.
        cache: where the model's reach family is kept (the process's,
            :func:`~comanip.estimation.model_reaches.model_families.default_families`, when None). Building it takes a second
            or so once per model and width, in the constructor.
        explanations: the explanations asked in order (module docstring); None: those ``options.timing`` names.
        person: what is known of the person (:class:`~comanip.estimation.calibration.person_calibration.PersonCalibration`),
            learned from each finished reach (:meth:`finish_reach`, which :meth:`reset` calls) and applied to the
            estimates; pass one to several estimators to share it. None: a person not seen yet.
    """

    def __init__(self, model: ReachingModel | Planner, start, *, prior_goal=None, prior_std=None, width: float | None = None,
                 options: OnlineOptions | None = None, cache: FamilyCache | None = None,
                 explanations: Sequence[Explanation] | None = None, person: PersonCalibration | None = None):
        if person is not None and not isinstance(person, PersonCalibration):
            raise ValueError(f"person must be a PersonCalibration or None, got {type(person).__name__}")
        self.person = person if person is not None else PersonCalibration()
        """What the estimator has learned of the person (:mod:`comanip.estimation.calibration.person_calibration`)."""
        self.options = options or OnlineOptions()
        if not isinstance(self.options, OnlineOptions):
            raise ValueError(f"options must be an OnlineOptions, got {type(self.options).__name__}")
        checked_model(model)
        body = (model.model if isinstance(model, Planner) else model).body
        if not body.is_linear:
            raise ValueError(f"OnlineGoalEstimator needs a point-mass model (linear dynamics), got the {body.name!r} body; "
                             "use comanip.estimate_goal for arms")
        families = (cache or default_families()).families(model)
        self.planner = families.planner
        self.model = model = self.planner.model
        n, d = model.n, model.d
        _, _, width = self.planner.check_inputs(start, np.zeros(d), width)
        self.width = width
        self.prior_goal = None if prior_goal is None else as_vector("prior_goal", prior_goal, d, "task-space position, m")
        self.prior_cov = prior_covariance(prior_std, model, width)
        o = self.options
        self.family = families.family(width, o.family_distances, o.family_size, o.family_tolerance)
        if any(a >= n for a in self.options.led_axes):
            raise ValueError(f"options.led_axes must be axes 0..{n - 1} of the hand position, got {self.options.led_axes!r}")
        self._person_axes = [a for a in range(n) if a not in self.options.led_axes]
        """The axes the person leads: what the calibration learns from and applies to (a partner leads the others)."""
        self.explanations = (list(explanations) if explanations is not None
                             else default_explanations(self.model, self.options, self.family))
        self._at_rest_first = bool(self.explanations) and isinstance(self.explanations[0], HandAtRest)
        self._blas = SingleThreadBlas()
        self._hand = HandTrace(d)
        self.reset(start)

    def reset(self, start=None, *, prior_goal=_SAME) -> None:
        """Forget every observation and start a new reach from ``start`` (nx,) or [q; qdot] (2n,), at rest (None:
        at rest where the hand was last seen, or where the last reach started). The reach before is learned from
        first (:meth:`finish_reach`); what is known of the person stays (:meth:`forget_person` forgets it). The
        model, width, prior std, options and reach family stay. ``prior_goal``: the prior goal g_bar (d,) m from
        this reach on, or None for the start's hand position; left out, the one before stays."""
        if hasattr(self, "_history"):                       # not on the first reach, from the constructor
            self.finish_reach()
        if prior_goal is not _SAME:
            self.prior_goal = None if prior_goal is None else as_vector("prior_goal", prior_goal, self.model.d,
                                                                        "task-space position, m")
        model, n = self.model, self.model.n
        if start is None:
            position = self._hand.last_observation[:n] if self._hand.count else self.start_position
            start = np.r_[position, np.zeros(model.state_size - n)]
        start, _, _ = self.planner.check_inputs(start, np.zeros(model.d), self.width)
        if np.any(start[n:] != 0):
            raise ValueError("start must be at rest (zero velocity and activation), got "
                             f"{start[n:].tolist()} after the position: the online estimator's plans start from rest")
        self.start = start
        self.start_position = start[:n].copy()
        self.prior_mean = self.start_position.copy() if self.prior_goal is None else self.prior_goal
        self.reach = Reach(self.family, start, self.prior_mean, self.prior_cov)
        smoothing = self.options.goal_smoothing
        self._smoother = None if smoothing is None else GoalSmoother(smoothing, self.start_position)
        for explanation in self.explanations:
            explanation.reset(self.reach)
        self._hand = HandTrace(model.d)
        self._history: list[tuple] = []    # (t, hand, goal, covariance, stop) of each estimate, before calibration
        self._forecasts: list[tuple] = []  # (positions (L, d), covariances (L, d, d)) of its forecast at the leads
        self._last_time = -math.inf
        self._planned = None      # (goal and timing, prediction, timed plan) of the last estimate's reach
        self._warned = False
        self._latest: OnlineEstimate | None = None
        self._rest_pending = False     # an at-rest observation's estimate not made yet (observe)

    def finish_reach(self) -> ReachFactors | None:
        """Learn from the reach so far as a finished one (:meth:`PersonCalibration.learn`) where its hand came to
        rest away from its start (:func:`~comanip.estimation.hand_rest.resting_position`): where it rests is the
        endpoint, the last time it moved faster than 5 % of its peak speed the stop. Once per reach; None where
        nothing was learned."""
        hand, history, forecasts = self._hand, self._history, self._forecasts
        self._history, self._forecasts = [], []
        if not history or len(forecasts) != len(history) or not hand.has_left(self.start_position):
            return None
        end, onset = resting_position(hand.t, hand.position, creep=MOVING_SPEED), hand.onset()
        speed = np.linalg.norm(hand.velocity, axis=1)
        if end is None or onset is None or speed.max() <= 0:
            return None
        end_s = float(hand.t[np.flatnonzero(speed >= 0.05 * speed.max())[-1]])
        t, hands, goals, covariances, stops = (np.array(column) for column in zip(*history))
        ahead, ahead_covariances = (np.array(column) for column in zip(*forecasts))
        axes = self._person_axes                 # a partner's axes say nothing of the person
        return self.person.learn(FinishedReach(self.start_position[axes], end[axes], onset, end_s, t, hands[:, axes],
                                               goals[:, axes], covariances[..., axes, :][..., axes], stops,
                                               ahead[..., axes], ahead_covariances[..., axes, :][..., axes],
                                               hand.t.copy(), hand.position[:, axes].copy()))

    def forget_person(self) -> None:
        """Forget what was learned of the person: the next reaches are a new person's."""
        self.person.forget()

    @property
    def observation_count(self) -> int:
        """Observations received so far."""
        return self._hand.count

    def update(self, time_s, position, velocity) -> OnlineEstimate:
        """Add an observation and re-estimate the goal.

        Args:
            time_s: time since the reach's start (s), ≥ 0 and after the previous observation's; any time, not
                only on the planning grid (after the horizon H·h it is read at the last step).
            position: observed hand position (d,), m.
            velocity: observed hand velocity (d,), m/s.

        A sample the tracker lost (position or velocity all NaN) is skipped: the previous estimate is returned
        unchanged (before any tracked sample, the prior with status ``uninformative``) and the next good
        sample carries on. A position or velocity with some entries NaN is refused (ValueError). Units that
        look like ms or mm (a time over a minute, a hand over 3 m from its start or at over 50 m/s) and a
        hand beyond a person's reach (1 m) are warned about, once per reach.

        Returns:
            An :class:`~comanip.estimation.online.online_estimate.OnlineEstimate`: g_hat (d,) m and its
            ``goal_covariance`` (d, d) m², ``t_obs`` the latest time, the forecast of the hand and its ``path``
            (what a robot follows), ``observation_residual`` the model's [q; qdot] at that time minus the
            observed one (2n,). Never raises for a failed solve: then ``success`` is False, the status
            says why and the goal and covariance are the previous estimate's (or the prior's).
        """
        t_begin = time.perf_counter()
        checked = self._checked(time_s, position, velocity)
        if checked is None:
            if self.latest is None:
                return self._result(Explained.explaining(self.prior_mean, self.prior_cov, EstimateStatus.UNINFORMATIVE,
                                                         "no tracked sample yet: the estimate is the prior"), t_begin)
            return self.latest
        return self._added_and_estimated(t_begin, *checked, forecast=True)

    def observe(self, times_s, positions, velocities) -> None:
        """Add observations whose estimates are not read (a reach's lead, given before its newest sample): each
        checked as :meth:`update` checks it, and estimated only where a later estimate could depend on it. While
        the hand has not left its start and :class:`~comanip.estimation.online.explanations.HandAtRest` is the first
        explanation, the estimate is the prior, which no explanation is asked for: it is made, without the
        forecast of the hand, when :attr:`latest` is next read. From the first observation that has left the start
        on, each is estimated as it is added, without the forecast where the estimate is the prior. The estimates
        of the later updates are those after one :meth:`update` per observation.

        Args:
            times_s: (K,) s since the reach's start, increasing, after the previous observation's.
            positions: (K, d) m.
            velocities: (K, d) m/s.
        """
        times, positions, velocities = (np.asarray(value, dtype=float) for value in (times_s, positions, velocities))
        if not (times.ndim == 1 and positions.shape == velocities.shape == (len(times), self.model.d)):
            raise ValueError(f"observe takes times (K,) s, positions and velocities (K, {self.model.d}) m and m/s, got "
                             f"shapes {times.shape}, {positions.shape} and {velocities.shape}")
        if len(times) and not self._checked_at_once(times, positions, velocities):
            times, positions, velocities = self._checked_in_turn(times, positions, velocities)
        resting = 0                                         # the leading rows at rest, added at once
        if len(times) and self._at_rest_first and not self._hand.has_left(self.start_position):
            offset = positions - self.start_position
            left = (offset * offset).sum(axis=1) > REST_RADIUS_M ** 2
            resting = int(np.argmax(left)) if left.any() else len(times)
            if resting:
                self._hand.extend(times[:resting], positions[:resting], velocities[:resting])
                self._last_time, self._rest_pending = float(times[resting - 1]), True
        for time_s, position, velocity in zip(times[resting:], positions[resting:], velocities[resting:]):
            self._added_and_estimated(time.perf_counter(), float(time_s), position, velocity, forecast=False)

    def _checked_in_turn(self, times: np.ndarray, positions: np.ndarray, velocities: np.ndarray) -> tuple:
        """The rows of (K,) s, (K, d) m, (K, d) m/s checked one by one (:meth:`_checked`, each after the one
        before), none added: those the tracker did not lose, as (K',) s, (K', d) m, (K', d) m/s."""
        before, kept = self._last_time, []
        try:
            for row in zip(times, positions, velocities):
                checked = self._checked(*row)
                if checked is not None:
                    kept.append(checked)
                    self._last_time = checked[0]
        finally:
            after, self._last_time = self._last_time, before
        if not kept:
            self._last_time = after                         # a lost sample's time, before any tracked one
            return times[:0], positions[:0], velocities[:0]
        return tuple(np.array(column) for column in zip(*kept))

    def _checked_at_once(self, times: np.ndarray, positions: np.ndarray, velocities: np.ndarray) -> bool:
        """Whether every row of (K,) s, (K, d) m, (K, d) m/s passes :meth:`_checked` without a word: all finite, the
        times increasing from after the previous observation's, and none that :meth:`_check_plausible` warns of."""
        if not (np.all(np.isfinite(times)) and np.all(np.isfinite(positions)) and np.all(np.isfinite(velocities))
                and times[0] >= 0 and times[0] > self._last_time and np.all(np.diff(times) > 0)):
            return False
        if self._warned:
            return True
        offset = positions - self.start_position
        return bool(times[-1] <= MAX_REACH_DURATION_S
                    and (offset * offset).sum(axis=1).max() <= MAX_HUMAN_REACH_M ** 2
                    and (velocities * velocities).sum(axis=1).max() <= (10 * MAX_HUMAN_HAND_SPEED_M_S) ** 2)

    @property
    def latest(self) -> OnlineEstimate | None:
        """The last estimate, None before the first update."""
        if self._rest_pending:
            self._rest_pending = False
            self._latest = self._result(self.explanations[0].explain(self._hand, self._latest), time.perf_counter(),
                                        with_forecast=False)
        return self._latest

    def _added_and_estimated(self, t_begin: float, time_s: float, position: np.ndarray, velocity: np.ndarray,
                             forecast: bool) -> OnlineEstimate:
        """A checked observation added and estimated (the at-rest estimate before it made first, since the
        explanations read it): the estimate."""
        if self._rest_pending:
            self.latest                                     # noqa: B018 (made from the trace before this observation)
        self._add(time_s, position, velocity)
        with self._blas:                                    # threads only slow products of this size down
            self._latest = self._estimate(t_begin, forecast)
        return self._latest

    def _add(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> None:
        self._last_time = time_s
        self._hand.append(time_s, position, velocity)

    def _checked(self, time_s, position, velocity) -> tuple[float, np.ndarray, np.ndarray] | None:
        """The observation checked by :meth:`update`'s rules: (time_s s, position (d,) m, velocity (d,) m/s); None
        for a sample the tracker lost."""
        model = self.model
        if isinstance(time_s, bool) or not isinstance(time_s, (int, float, np.integer, np.floating)) or not math.isfinite(time_s):
            raise ValueError(f"time_s must be a finite time in s since the start, got {time_s!r}")
        time_s = float(time_s)
        if time_s < 0:
            raise ValueError(f"time_s must be ≥ 0 s (time since the reach's start), got {time_s:g}")
        if time_s < self._last_time:
            raise ValueError(f"time_s must not go backwards: got {time_s:g} s after an observation at {self._last_time:g} s")
        if lost_sample(position) or lost_sample(velocity):
            # a sample the tracker lost: skipped, the estimate stands until the next good one
            if self.latest is None:
                self._last_time = time_s
            return None
        position = as_vector("position", position, model.d, "hand position, m")
        velocity = as_vector("velocity", velocity, model.d, "hand velocity, m/s")
        if time_s == self._last_time:
            raise ValueError(f"time_s {time_s:g} s repeats the previous observation's time; each observation needs its "
                             "own time (a sample sent twice: send it once)")
        self._check_plausible(time_s, position, velocity)
        return time_s, position, velocity

    def _check_plausible(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> None:
        """A warning, once per reach, for an observation no person's reach makes: a time over a minute since
        the start (ms?), a hand over 3 m from its start or at over 50 m/s (mm?), or beyond a person's reach."""
        if self._warned:
            return
        distance, speed, problem = float(np.linalg.norm(position - self.start_position)), float(np.linalg.norm(velocity)), None
        if time_s > MAX_REACH_DURATION_S:
            problem = (f"time_s {time_s:g} s is longer than one reach ({MAX_REACH_DURATION_S:g} s at most): is it in ms "
                       "(comanip takes s), or is this the next reach (reset())?")
        elif distance > MAX_REACH_SPAN_M or speed > 10 * MAX_HUMAN_HAND_SPEED_M_S:
            problem = (f"the hand is {distance:.3g} m from its start at {speed:.3g} m/s, beyond any reach (at most "
                       f"{MAX_REACH_SPAN_M:g} m, about {MAX_HUMAN_HAND_SPEED_M_S:g} m/s): is it in mm and mm/s (comanip "
                       "takes m and m/s)?")
        elif distance > MAX_HUMAN_REACH_M:
            problem = (f"the hand is {distance:.3g} m from its start, beyond a person's reach of about "
                       f"{MAX_HUMAN_REACH_M:g} m: is the start right, or is this the next reach (reset())?")
        if problem is not None:
            self._warned = True
            warnings.warn(problem, stacklevel=3)

    def _estimate(self, t_begin: float, forecast: bool) -> OnlineEstimate:
        """The first explanation that explains the hand gives the estimate; none: the prior."""
        reasons = []
        for explanation in self.explanations:
            explained = explanation.explain(self._hand, self.latest)
            if explained.explains:
                return self._result(explained, t_begin, reasons, forecast)
            reasons.append(explained.message)
        return self._result(Explained.explaining(self.prior_mean, self.prior_cov, EstimateStatus.UNINFORMATIVE,
                                                 "the estimate is the prior"), t_begin, reasons, forecast)

    def _person_acceleration(self) -> np.ndarray:
        """The hand's acceleration (d,) m/s² from its last velocities, NaN on the axes a robot leads
        (``options.led_axes``: their motion is the robot's, which the forecast must not feed back)."""
        acceleration = recent_acceleration(self._hand.t, self._hand.velocity)
        acceleration[list(self.options.led_axes)] = np.nan
        return acceleration

    def _planned_reach(self, goal: np.ndarray, timing) -> tuple:
        """The model's reach to ``goal`` (:meth:`Reach.prediction`) and that reach played at ``timing``: the last
        update's where its goal and timing were the same (the prior's, while the hand rests), its arrays read-only
        since successive estimates then share them."""
        key = (goal.tobytes(), timing)
        if self._planned is None or self._planned[0] != key:
            prediction = self.reach.prediction(goal, order=0)
            timed = timed_plan(prediction.mean, prediction.cov, prediction.torque, self.model.h, self.model.n, timing)
            for array in (*timed, prediction.mean, prediction.cov, prediction.torque):
                array.flags.writeable = False
            self._planned = (key, prediction, timed)
        return self._planned[1], self._planned[2]

    def _result(self, explained: Explained, t_begin: float, reasons: Sequence[str] = (),
                with_forecast: bool = True) -> OnlineEstimate:
        """The estimate of ``explained``, with the model's predicted reach to its goal and the forecast of the hand
        (``with_forecast``: :meth:`update`'s ``forecast``); its message follows why the explanations asked before it did not explain
        the hand."""
        model, n = self.model, self.model.n
        status, observed = explained.status, self._hand.last_observation
        stop = None if explained.timing is None else explained.timing.onset_s + explained.timing.movement_time_s
        goal, covariance = np.array(explained.goal, dtype=float), np.array(explained.covariance, dtype=float)
        if status != EstimateStatus.UNINFORMATIVE:
            self._history.append((self._last_time, observed[:n].copy(), goal, covariance, math.nan if stop is None else stop))
            goal, covariance = self.person.goal(observed[:n], goal, covariance, self._person_axes)
            stop = None if stop is None else self.person.stop(self._last_time, stop)
        unsmoothed = goal, covariance
        if self._smoother is not None:
            if status == EstimateStatus.UNINFORMATIVE:      # the prior: not where the hand heads
                self._smoother.reset()
            else:
                goal, covariance = self._smoother.smooth(self._last_time, goal, covariance, observed[:n])
        prediction, timed = self._planned_reach(goal, explained.timing)
        step, fraction = grid_position(max(self._last_time - timed.t[0], 0.0), timed.t[1] - timed.t[0], model.H)
        predicted = (1 - fraction) * timed.mean[step, :2 * n] + fraction * timed.mean[min(step + 1, model.H), :2 * n]
        forecast = None
        path = ForecastPoint(timed.t, timed.mean[:, :n], timed.mean[:, n:2 * n], timed.cov[:, :n, :n])
        if self._hand.count and (with_forecast or status != EstimateStatus.UNINFORMATIVE):
            forecast = continued_reach(self.family, self.start_position, self._last_time, observed[:n], observed[n:], goal,
                                       covariance, stop, self._person_acceleration(), member=prediction.member)
            if status != EstimateStatus.UNINFORMATIVE:
                ahead = forecast.at(self._last_time + np.array(FORECAST_LEADS))
                self._forecasts.append((ahead.position, ahead.covariance))
            if self.person.forecast_spread != 1.0:
                blocks = forecast.cov.shape[-1] // n             # the person's axes in every state block
                axes = [block * n + a for block in range(blocks) for a in self._person_axes]
                forecast = dataclasses.replace(forecast, cov=scaled_on_axes(forecast.cov, self.person.forecast_spread, axes))
            path = within_horizon(forecast, self.options.forecast_horizon)
        return OnlineEstimate(goal=goal, goal_covariance=covariance, status=status,
                              message="; ".join([*reasons, explained.message]), t_obs=self._last_time, path=path,
                              forecast=forecast, timed_reach=timed, observed_state=observed,
                              observation_residual=predicted - observed, prior_goal=self.prior_goal,
                              unsmoothed_goal=unsmoothed[0], unsmoothed_goal_covariance=unsmoothed[1],
                              start=self.start.copy(), width=self.width, model_name=model.name,
                              solve_time=time.perf_counter() - t_begin, iterations=explained.iterations)
