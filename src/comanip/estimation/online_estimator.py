"""Continuous goal estimation: the goal of a reach in progress, revised with every observation.

A person at rest at s_0 reaches for an unknown goal g; positions and velocities of their hand arrive one at a
time, at any times t_k ≥ 0. After each, :meth:`OnlineGoalEstimator.update` returns the maximum a posteriori
goal g_hat under the model and its covariance, with the model's predicted reach to g_hat:

    g_hat = argmin_g  ½ |L^-1 (y - mu(g))|² + ½ (g - g_bar)^T P0^-1 (g - g_bar)

where mu(g) stacks the plan's predicted mean [q; qdot] at the observation times (linearly interpolated
between grid steps), L is the factor of the observations' joint covariance under the plan's open-loop belief
(or that of a person who corrects deviations, ``OnlineOptions.correction_time``:
:mod:`comanip.estimation.corrected_deviation`) plus the observation noise R
(:mod:`comanip.estimation.observation_whitening`), and (g_bar, P0) the prior
(:mod:`comanip.estimation.goal_prior`). Every observation so far enters. The observations' covariance is that
of the plan to a goal within 5 % of the distance of the estimate (``OnlineOptions.covariance_tolerance``; its
dependence on g is left out of the objective, as in iteratively reweighted least squares: an exact
observation of a plan then gives back its goal). The minimum is found by Newton's method with the exact
Hessian (the Gauss–Newton matrix where that is not positive definite), warm-started from the previous
estimate. The goal's covariance is the Laplace approximation, the inverse Hessian at the estimate; where the
distance is still poorly known (relative std along the reach above 5 %) its variance along the reach comes
from a 1-D quadrature of the posterior along the line from the start through g_hat, and the spread across
the reach is scaled by the root-mean-square distance over |g_hat - x_0| (the curvature at the mode misses the
posterior's long tail towards far goals). How often its 95 % ellipsoid holds the true goal of reaches
sampled from the model is measured on docs/results/calibration.md (under the belief of a person who corrects
it needs ``OnlineOptions.covariance_scale``). Axes someone else moves (``OnlineOptions.led_axes``, the sync
robot's z) count for less while they move.

That estimate assumes the reach started at t = 0 at the model's pace. People start when they like, move at
their own pace and shape, pause and correct. With ``OnlineOptions(timing="estimated")`` (the default) each
update weighs three explanations of the hand in turn: the model at its own pace (the estimate above) while
its whitened misfit stays small and no settled fit of the model's reach at a free pace contradicts it; the
model's reach at the person's own pace and onset (:mod:`comanip.estimation.paced_model`) where that explains
the hand; else the model fitted to recorded people (:mod:`comanip.estimation.people_model`, status
``people_model``). Goals from the last two are combined with the prior and never lie behind a hand that has
moved past them, and their covariance is that of where the hand will stop (for the paced fit, its own plus
the spread of the model's reach around its goal at the end).

The plans come from a :class:`~comanip.estimation.reach_family.ReachFamily` of the model, built once per model
and width: for a rotation-invariant point mass from rest, the plan to any goal is a 1-D reach turned onto its
direction, read from a spline over distance, together with d mu / d g. So an update needs no plan solve.
What is approximated: the predicted reach is the spline's, within ``family.interpolation_error`` (m, measured
at build time against real plans; about 1e-4 m or less on the paper presets) of the model's plan; an
observation between grid steps sees the state interpolated linearly between the steps around it (mean and
error alike, :mod:`comanip.estimation.observation_whitening`). The first (cold) estimate starts from the best
family member along the observed directions.

>>> estimator = OnlineGoalEstimator(comanip.presets.cartesian(), np.zeros(6))
>>> estimate = estimator.update(0.1, position, velocity)
>>> estimate.goal, estimate.goal_covariance, estimate.mean
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2
from threadpoolctl import ThreadpoolController

from comanip.arguments import as_count, as_positive, as_vector
from comanip.belief.propagation import linearised_step_function
from comanip.estimation.corrected_deviation import (CORRECTION_TIME, DEVIATION_TIME, corrected_covariance, corrected_powers,
                                                   correction_factor)
from comanip.estimation.goal_estimate import GoalEstimate
from comanip.estimation.goal_prior import prior_covariance
from comanip.estimation.hand_rest import REST_RADIUS_M, has_left, lost_sample
from comanip.estimation.map_goal import MapNewton, MapProblem
from comanip.estimation.observation import OBSERVATION_STD, observation_covariance
from comanip.estimation.observation_whitening import ObservationWhitening
from comanip.estimation.endpoint_baselines import MOVING_SPEED
from comanip.estimation.paced_model import PacedFit, PacedModel
from comanip.estimation.people_model import PeopleModel, shipped_people_model
from comanip.estimation.profile_fit import detected_onset
from comanip.estimation.reach_family import ReachFamily, ReachPrediction
from comanip.estimation.estimation_planner import checked_model, estimation_planner
from comanip.model import ReachingModel
from comanip.optim import CONVERGED, Status
from comanip.plausibility import MAX_HUMAN_HAND_SPEED_M_S, MAX_HUMAN_REACH_M
from comanip.units import MAX_REACH_DURATION_S, MAX_REACH_SPAN_M
from comanip.caching.model_cache import ModelCache
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner


TIMINGS = ("estimated", "model")
"""The values of :attr:`OnlineOptions.timing`."""


@dataclass(frozen=True)
class OnlineOptions:
    """How the online estimator works."""

    observation_std: tuple[float, float] = OBSERVATION_STD
    """Observation noise R: standard deviation of a measured position (m) and velocity (m/s)."""
    family_distances: tuple[float, float] = (0.005, 1.0)
    """Range of goal distances from the start (m) the reach family covers."""
    family_size: int = 32
    """Members the reach family starts from (it adds more where the spline is not accurate enough)."""
    family_tolerance: float = 1e-4
    """Largest difference (m) accepted between the family's interpolated mean position and a real plan."""
    tolerance: float = 1e-7
    """A Newton goal step shorter than this (m), or one that lowers -log p by less than 1e-6 (taken, then stop), ends an update."""
    max_iterations: int = 20
    """Newton iterations per round under one whitening (an update runs up to three rounds, rebuilding the
    whitening when the estimate moved; ``GoalEstimate.iterations`` counts them all)."""
    step_fraction: float = 0.5
    """Largest goal step, as a fraction of the distance from the start to the current goal (at least one width)."""
    covariance_tolerance: float = 0.05
    """The belief covariance that weighs the observations is the plan's to a goal within this fraction of the
    distance (start to goal) of the estimate; it is recomputed when the estimate moves farther."""
    correction_time: float | None = None
    """Time constant (s) with which the person corrects a deviation from their plan
    (:mod:`comanip.estimation.corrected_deviation`); None: the plan's open-loop belief, a deviation persists.
    The sync scenario's continuous policy uses CORRECTION_TIME (0.3 s) of that module (ROBOT_BELIEF)."""
    deviation_time: float = 0.0
    """With a correction time: the person strays from the plan by about this many seconds (s) of their motion,
    in any direction (ahead, behind, across; :mod:`comanip.estimation.corrected_deviation`); 0: only motor noise.
    The sync scenario's continuous policy uses DEVIATION_TIME (0.15 s) of that module."""
    led_axes: tuple[int, ...] = ()
    """Axes (indices into the hand position, 0..d-1) along which someone else moves the hand, e.g. the robot
    that leads z in the sync scenario: there the observed motion is partly theirs, not the person's reach, and
    strays from the person's plan by ``led_deviation_time`` seconds of its motion instead of
    ``deviation_time`` (it counts for less while the hand moves; at rest it still pins the goal). Needs a
    correction time. Empty: every axis is the person's."""
    led_deviation_time: float = 0.3
    """sigma_t (s) along the ``led_axes`` (:mod:`comanip.estimation.corrected_deviation`)."""
    led_from: float = 0.0
    """Time (s since the reach's start) from which someone else leads the ``led_axes``; before it they are the
    person's (the sync robot leads z from t_o)."""
    covariance_scale: float = 1.0
    """The reported goal covariance is the Laplace (and quadrature) one times this factor (the estimate itself
    is unchanged). 1: as computed, calibrated for the open-loop belief. Under a correction time it is not: on
    reaches sampled from that process most ellipsoids are too wide and about a tenth far too narrow (87–88 %
    pooled coverage of the 95 % ellipsoid at 0.2–0.8 s); the sync robot's belief uses 3
    (comanip.simulation.policies.continuous.ROBOT_BELIEF; studies/is_the_goal_covariance_calibrated/measure_goal_estimation.py --belief robot)."""

    timing: str = "estimated"
    """"model": the reach starts at t = 0 and moves at the model's pace (the estimate above, exact for the
    model's own reaches). "estimated": that estimate while the model at its own pace explains the observations
    (whitened misfit at most ``mismatch_threshold``, and the model's timing not rejected by a fit of its reach
    at a free pace and onset); from the first update on which it does not, the model's reach at the person's
    own pace and onset (:mod:`comanip.estimation.paced_model`) where that explains the hand (misfit at most
    ``paced_threshold``), else the model fitted to recorded people (:mod:`comanip.estimation.people_model`),
    status ``people_model``. Goals from either are combined with the prior."""
    mismatch_threshold: float = 9.0
    """With ``timing="estimated"``: the largest mean squared whitened residual (per observed number) at which
    the model at its own pace still explains the observations (about 1 for the model's own reaches)."""
    people_model: PeopleModel | None = None
    """With ``timing="estimated"``: the model of people's movements (:class:`comanip.estimation.people_model.PeopleModel`,
    e.g. fitted to your own recordings); None: the one that ships with comanip for the kind of movement the
    reaching model makes (``arm``, fitted to arm reaches, for a 3-D model; ``mouse`` for a 2-D one). A model
    fitted to mouse movements is refused for a 3-D reach."""
    paced_threshold: float = 0.05
    """With ``timing="estimated"``: the largest misfit (chi² per observed number, :mod:`comanip.estimation.profile_fit`)
    at which the model's reach at the person's pace explains the observations."""

    def __post_init__(self):
        observation_covariance(self.observation_std, 1)
        if self.timing not in TIMINGS:
            raise ValueError(f"timing must be one of {TIMINGS}, got {self.timing!r}")
        as_positive("mismatch_threshold", self.mismatch_threshold, "mean squared whitened residual")
        as_positive("paced_threshold", self.paced_threshold, "chi² per observed number")
        if self.people_model is not None and not isinstance(self.people_model, PeopleModel):
            raise ValueError(f"people_model must be a PeopleModel or None, got {type(self.people_model).__name__}")
        if not (math.isfinite(self.led_from) and self.led_from >= 0):
            raise ValueError(f"led_from must be a finite time ≥ 0 s, got {self.led_from!r}")
        if not (math.isfinite(self.led_deviation_time) and self.led_deviation_time >= 0):
            raise ValueError(f"led_deviation_time must be a finite time ≥ 0 s, got {self.led_deviation_time!r}")
        axes = tuple(self.led_axes)
        if any(isinstance(a, bool) or not isinstance(a, (int, np.integer)) or a < 0 for a in axes) or len(set(axes)) != len(axes):
            raise ValueError(f"led_axes must be distinct axis indices ≥ 0 of the hand position, got {self.led_axes!r}")
        if axes and self.correction_time is None:
            raise ValueError("led_axes need a correction_time (their motion strays as a person who corrects does), got None")
        as_positive("covariance_scale", self.covariance_scale, "factor")
        low, high = (as_positive(f"family_distances[{k}]", v, "m") for k, v in enumerate(self.family_distances))
        if low >= high:
            raise ValueError(f"family_distances must be (D_min, D_max) with D_min < D_max (m), got {self.family_distances!r}")
        as_count("family_size", self.family_size, 4)
        as_positive("family_tolerance", self.family_tolerance, "m")
        as_positive("tolerance", self.tolerance, "m")
        as_count("max_iterations", self.max_iterations)
        as_positive("step_fraction", self.step_fraction, "fraction")
        as_positive("covariance_tolerance", self.covariance_tolerance, "fraction of the distance")
        if self.correction_time is not None:
            as_positive("correction_time", self.correction_time, "s (or None: open loop)")
        if not (math.isfinite(self.deviation_time) and self.deviation_time >= 0):
            raise ValueError(f"deviation_time must be a finite time ≥ 0 s, got {self.deviation_time!r}")


CORRECTING_PERSON = OnlineOptions(correction_time=CORRECTION_TIME, deviation_time=DEVIATION_TIME)
"""The options for a person who corrects deviations from their plan (:mod:`comanip.estimation.corrected_deviation`):
what the sync scenario's continuous policy, the handover's estimate trigger and the ROS node use."""


class ModelFamilies:
    """A model's planner and its reach families, one per (width, family options)."""

    def __init__(self, model: ReachingModel | Planner):
        self.planner = estimation_planner(model)
        self._families: dict[tuple, ReachFamily] = {}

    def family(self, width: float, options: OnlineOptions) -> ReachFamily:
        key = (float(width), options.family_distances, options.family_size, options.family_tolerance)
        if key not in self._families:
            self._families[key] = ReachFamily(self.planner, width, options.family_distances, options.family_size,
                                              options.family_tolerance)
        return self._families[key]


class FamilyCache(ModelCache[ModelFamilies]):
    """Reach families kept between online estimators: by the model's parameters (a Planner is its own key)."""

    def __init__(self, size: int = 4):
        super().__init__(ModelFamilies, size)

    def key(self, model):
        return model if isinstance(model, Planner) else super().key(model)

    def families(self, model: ReachingModel | Planner) -> ModelFamilies:
        return self.get(checked_model(model))


DEFAULT_FAMILIES = FamilyCache()
"""The cache :class:`OnlineGoalEstimator` uses when given none."""

#: A paced fit whose relative std of the goal's distance is at most this pins the goal.
SETTLED_SPREAD = 0.1
#: Observations since the onset a paced fit needs to pin the goal.
SETTLED_OBSERVATIONS = 8
#: |log pace|, and |onset delay| / MT, beyond which a settled paced fit contradicts the model's own timing.
PACE_TOLERANCE = 0.14
#: Whitenings rebuilt per update at most (each at the goal the previous round ended at).
_COVARIANCE_ROUNDS = 3


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
        options: :class:`OnlineOptions`.
        cache: where the model's reach family is kept (:data:`DEFAULT_FAMILIES` when None). Building it costs
            about 1 s (Cartesian preset) once per model and width, in the constructor.
    """

    def __init__(self, model: ReachingModel | Planner, start, *, prior_goal=None, prior_std=None, width: float | None = None,
                 options: OnlineOptions | None = None, cache: FamilyCache | None = None):
        self.options = options or OnlineOptions()
        if not isinstance(self.options, OnlineOptions):
            raise ValueError(f"options must be an OnlineOptions, got {type(self.options).__name__}")
        checked_model(model)
        body = (model.model if isinstance(model, Planner) else model).body
        if not body.is_linear:
            raise ValueError(f"OnlineGoalEstimator needs a point-mass model (linear dynamics), got the {body.name!r} body; "
                             "use comanip.estimate_goal for arms")
        families = (cache or DEFAULT_FAMILIES).families(model)
        self.planner = families.planner
        self.model = model = self.planner.model
        n, d = model.n, model.d
        _, _, width = self.planner.check_inputs(start, np.zeros(d), width)
        self.width = width
        self.prior_goal = None if prior_goal is None else as_vector("prior_goal", prior_goal, d, "task-space position, m")
        self.prior_cov = prior_covariance(prior_std, model, width)
        self._prior_precision = np.linalg.inv(self.prior_cov)
        self.family = families.family(width, self.options)
        _, A, _ = linearised_step_function(model.body, model.h)(np.zeros(model.state_size), np.zeros(n))
        A = np.asarray(A)
        correction_time = self.options.correction_time
        self._rho = 1.0 if correction_time is None else correction_factor(correction_time, model.h)
        self._A = A
        self._powers = corrected_powers(A, self._rho, model.H)
        if any(a >= n for a in self.options.led_axes):
            raise ValueError(f"options.led_axes must be axes 0..{n - 1} of the hand position, got {self.options.led_axes!r}")
        self._R = observation_covariance(self.options.observation_std, n)
        # sigma_t of each step's increment (H, n): led axes stray more from the step that ends after led_from on
        self._deviation_times = np.full((model.H, n), self.options.deviation_time)
        led_steps = model.h * np.arange(1, model.H + 1) > self.options.led_from
        self._deviation_times[np.ix_(led_steps, list(self.options.led_axes))] = self.options.led_deviation_time
        self._paced = PacedModel(self.family)
        self._people = self._people_model(d)
        self._blas = ThreadpoolController()
        self.reset(start)

    def reset(self, start=None) -> None:
        """Forget every observation and start a new reach from ``start`` (nx,) or [q; qdot] (2n,), at rest (None:
        at rest where the hand was last seen, or where the last reach started). The model, width, prior std,
        options and reach family stay; a prior goal given at construction stays, else the prior mean is the new
        start."""
        model, n, H = self.model, self.model.n, self.model.H
        if start is None:
            position = self._last_observation[:n] if self._history else self.start_position
            start = np.r_[position, np.zeros(model.state_size - n)]
        start, _, _ = self.planner.check_inputs(start, np.zeros(model.d), self.width)
        if np.any(start[n:] != 0):
            raise ValueError("start must be at rest (zero velocity and activation), got "
                             f"{start[n:].tolist()} after the position: the online estimator's plans start from rest")
        self.start = start
        self.start_position = start[:n].copy()
        self.prior_mean = self.start_position.copy() if self.prior_goal is None else self.prior_goal
        self._counts = np.zeros(H + 1)
        self._fractions = np.zeros(H + 1)          # per step: summed fractions of a step of its observations
        self._sums = np.zeros((H + 1, 2 * n))
        self._weights = np.zeros((H + 1, H + 1))
        self._last_time = -math.inf
        self._last_observation = np.zeros(2 * n)
        self._history: list[np.ndarray] = []       # [t, position, velocity] of every observation, for the people model
        self._off_model: str | None = None          # why the model at its own pace does not explain the hand
        self._whitening: ObservationWhitening | None = None
        self._whitening_goal = np.zeros(model.d)
        self._whitened_observations = 0             # observations the whitening holds
        self._warned = False
        self.latest: GoalEstimate | None = None
        """The last estimate, None before the first update."""

    @property
    def observation_count(self) -> int:
        """Observations received so far."""
        return int(self._counts.sum())

    def update(self, time_s, position, velocity) -> GoalEstimate:
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
            A :class:`GoalEstimate`: the predicted reach from the start to g_hat (a Plan), ``goal_covariance``
            (d, d) m², ``t_obs`` the latest time, ``observation_residual`` the predicted [q; qdot] at that time
            minus the observed one (2n,). Never raises for a failed solve: then ``success`` is False, the status
            says why and the goal and covariance are the previous estimate's (or the prior's).
        """
        t_begin = time.perf_counter()
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
                return self._result(self.prior_mean, self.prior_cov, Status.UNINFORMATIVE,
                                    "no tracked sample yet: the estimate is the prior", 0, t_begin)
            return self.latest
        position = as_vector("position", position, model.d, "hand position, m")
        velocity = as_vector("velocity", velocity, model.d, "hand velocity, m/s")
        observation = np.r_[position, velocity]
        if time_s == self._last_time:
            raise ValueError(f"time_s {time_s:g} s repeats the previous observation's time; each observation needs its "
                             "own time (a sample sent twice: send it once)")
        self._check_plausible(time_s, position, velocity)
        before, fraction = _grid_position(time_s, model.h, model.H)
        self._counts[before] += 1
        self._sums[before] += observation
        self._fractions[before] += fraction
        self._weights[before, before] += 1.0 - fraction
        if fraction > 0:
            self._weights[before, before + 1] += fraction
        self._last_time, self._last_observation = time_s, observation
        self._history.append(np.r_[time_s, observation])
        with self._blas.limit(limits=1, user_api="blas"):   # threads only slow products of this size down
            self.latest = self._estimate(t_begin)
        return self.latest

    def _check_plausible(self, time_s: float, position: np.ndarray, velocity: np.ndarray) -> None:
        """A warning, once per reach, for an observation no person's reach makes: a time over a minute since
        the start (ms?), a hand over 3 m from its start or at over 50 m/s (mm?), or beyond a person's reach."""
        if self._warned:
            return
        distance = float(np.linalg.norm(position - self.start_position))
        speed = float(np.linalg.norm(velocity))
        problem = None
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

    def _estimate(self, t_begin: float) -> GoalEstimate:
        if self.options.timing == "model":
            return self._model_estimate(t_begin)[0]
        n = self.model.n
        history = np.asarray(self._history)
        t, position, velocity = history[:, 0], history[:, 1:1 + n], history[:, 1 + n:1 + 2 * n]
        if not has_left(position, self.start_position):
            # a tracker's noise makes a resting hand's velocities look like motion; its positions do not
            return self._result(self.prior_mean, self.prior_cov, Status.UNINFORMATIVE, "the hand has not left its "
                                f"start (within {1e3 * REST_RADIUS_M:g} mm): the estimate is the prior", 0, t_begin)
        onset = detected_onset(t, np.sqrt((velocity * velocity).sum(axis=1)), MOVING_SPEED)
        previous = self.latest
        if self._off_model is None:
            estimate, misfit = self._model_estimate(t_begin)
            if onset is None or misfit is None or not self._humanlike(position, velocity):
                return estimate
            paced = self._paced_fit(t, position, velocity, onset, estimate.goal)
            contradiction = self._contradiction(estimate, paced)
            if misfit <= self.options.mismatch_threshold and contradiction is None:
                return estimate
            self._off_model = contradiction or (f"the model at its own pace does not explain the hand (misfit {misfit:.3g} "
                                                f"per observed number)")
        elif onset is None:
            return self._result(self.prior_mean, self.prior_cov, Status.UNINFORMATIVE,
                                "no observation shows movement: the estimate is the prior", 0, t_begin)
        else:
            paced = self._paced_fit(t, position, velocity, onset, None if previous is None else previous.goal)
        if paced.misfit <= self.options.paced_threshold and self._settled(paced):
            # where the hand stops spreads around the goal as the model's own reach to it does at its end
            landing = self._prediction(paced.goal, order=0).cov[-1, :n, :n]
            goal, covariance = self._with_prior(self._not_behind(paced.goal, position[-1]), paced.covariance + landing)
            return self._result(goal, covariance, Status.SOLVED, f"{self._off_model}; the model's reach at the person's "
                                f"pace (×{paced.pace:.3g}, onset {paced.onset:.3g} s) does", 0, t_begin)
        people = self._people.predict(t, position, velocity, self.start_position)
        goal, covariance = self._with_prior(self._not_behind(people.goal, position[-1]), people.covariance)
        return self._result(goal, covariance, Status.PEOPLE_MODEL, f"{self._off_model}, nor does it clearly at the "
                            f"person's pace (misfit {paced.misfit:.3g}): the goal is the people model's", 0, t_begin)

    def _people_model(self, d: int) -> PeopleModel:
        """The people model for a reach in d dimensions (:attr:`OnlineOptions.people_model`)."""
        people = self.options.people_model or shipped_people_model("arm" if d == 3 else "mouse")
        if d == 3 and people.kind == "mouse":
            raise ValueError("options.people_model was fitted to mouse movements; a 3-D reach is an arm's: fit one "
                             "to arm reaches (PeopleModel.fit(recordings, kind='arm')) or leave it None")
        return people

    def _humanlike(self, position: np.ndarray, velocity: np.ndarray) -> bool:
        """Whether the observed hand stays within the reach family's distances and a person's hand speeds
        (beyond them no model explains it better than the model at its own pace, which says so)."""
        offset = position - self.start_position
        return bool(np.sqrt((offset * offset).sum(axis=1)).max() <= self.family.distances[-1]
                    and np.sqrt((velocity * velocity).sum(axis=1)).max() <= MAX_HUMAN_HAND_SPEED_M_S)

    def _settled(self, paced: PacedFit) -> bool:
        """Whether a paced fit pins the goal's distance: its relative std along the reach at most
        :data:`SETTLED_SPREAD` (before the speed peaks, a shorter quicker and a longer slower reach fit alike),
        from at least :data:`SETTLED_OBSERVATIONS` observations since the onset."""
        if paced.observations < SETTLED_OBSERVATIONS:
            return False
        offset = paced.goal - self.start_position
        distance = float(np.linalg.norm(offset))
        return distance > 0 and math.sqrt(float(offset @ paced.covariance @ offset)) / distance**2 <= SETTLED_SPREAD

    def _contradiction(self, estimate: GoalEstimate, paced: PacedFit) -> str | None:
        """Why the model at its own pace is contradicted by its reach at the person's pace, or None: that fit
        explains the hand (misfit at most ``paced_threshold``), pins the goal (:meth:`_settled`), finds a pace
        off the model's by more than :data:`PACE_TOLERANCE` (as a log) or an onset off the model's by more
        than that fraction of the movement time, and a goal the model-pace estimate's 99.9 % region (with the
        paced fit's) does not hold."""
        on_time = abs(math.log(paced.pace)) <= PACE_TOLERANCE and abs(paced.delay) <= PACE_TOLERANCE * paced.duration
        if paced.misfit > self.options.paced_threshold or not self._settled(paced) or on_time:
            return None
        difference = paced.goal - estimate.goal
        distance2 = float(difference @ np.linalg.solve(paced.covariance + estimate.goal_covariance, difference))
        if distance2 <= chi2.ppf(0.999, len(difference)):
            return None
        return (f"the model at its own pace is contradicted by its reach at the person's pace (×{paced.pace:.3g}, "
                f"{paced.delay:+.3g} s late), "
                f"whose goal lies {math.sqrt(distance2):.3g} standard deviations away")

    def _paced_fit(self, t, position, velocity, onset: float, goal) -> PacedFit:
        """The model's reach fitted at the person's pace (:mod:`comanip.estimation.paced_model`), its shape tried
        at the distance of ``goal`` (kept between 1 and 3 times the hand's displacement: a shape far from the
        distance it fits can lock into a wrong pace and distance) and at 1.5 times the displacement."""
        displacement = max(float(np.linalg.norm(position[-1] - self.start_position)), 1e-3)
        guesses = [1.5 * displacement]
        if goal is not None:
            guesses.insert(0, min(max(float(np.linalg.norm(np.asarray(goal) - self.start_position)), displacement), 3 * displacement))
        return self._paced.fit(t, position, velocity, self.start_position, onset, guesses)

    def _not_behind(self, goal: np.ndarray, hand: np.ndarray) -> np.ndarray:
        """``goal`` moved along the line from the start through it up to the ``hand``'s projection on that line
        when the hand is farther along (a hand that has moved on is not heading for a goal behind it)."""
        offset = goal - self.start_position
        distance = float(np.linalg.norm(offset))
        if distance == 0:
            return goal
        along = float((hand - self.start_position) @ offset) / distance
        return goal + max(along - distance, 0.0) * offset / distance

    def _with_prior(self, goal: np.ndarray, covariance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A Gaussian goal estimate (d,) m, (d, d) m², combined with the prior (g_bar, P0)."""
        precision = np.linalg.inv(covariance) + self._prior_precision
        combined = np.linalg.inv(precision)
        return combined @ (np.linalg.solve(covariance, goal) + self._prior_precision @ self.prior_mean), combined

    def _model_estimate(self, t_begin: float) -> tuple[GoalEstimate, float | None]:
        """The estimate of the model at its own pace (module docstring) and its misfit (mean squared whitened
        residual per observed number; None when nothing was fitted)."""
        steps = np.flatnonzero(self._counts)
        counts = self._counts[steps]
        observed = self._sums[steps] / counts[:, None]
        weights = self._weights[steps] / counts[:, None]
        problem = MapProblem(self.family, lambda goal: self._prediction(goal, order=2, covariance=False), self.start_position,
                             self.prior_mean, self._prior_precision, steps, observed, weights)
        previous = self.latest
        try:
            if previous is None or previous.status in (Status.UNINFORMATIVE, Status.FAILED):
                goal = problem.cold_goal(self._last_observation, self.options.observation_std,
                                         self._R[None] / counts[:, None, None])
                if goal is None:
                    return self._result(self.prior_mean, self.prior_cov, Status.UNINFORMATIVE,
                                        "no observation shows movement: the estimate is the prior", 0, t_begin), None
            else:
                goal = previous.goal
            iterations = 0
            for _ in range(_COVARIANCE_ROUNDS):
                whitening = self._whitening_at(goal)
                solved = MapNewton(problem, whitening, self.options.tolerance, self.options.step_fraction,
                                   self.width).solve(goal, self.options.max_iterations)
                goal, covariance, status, message = solved.x, solved.local_model.covariance(), solved.status, solved.message
                iterations += solved.nit
                if not self._stale(goal):
                    break
            covariance = self.options.covariance_scale * problem.distance_spread(goal, covariance, whitening)
            if not (np.all(np.isfinite(goal)) and np.all(np.isfinite(covariance))):
                raise np.linalg.LinAlgError("non-finite estimate")
            misfit = problem.misfit(whitening, goal) if self.options.timing == "estimated" else None
        except np.linalg.LinAlgError as error:
            self._whitening = None
            goal, covariance = (self.prior_mean, self.prior_cov) if previous is None else (previous.goal, previous.goal_covariance)
            return self._result(goal, covariance, Status.FAILED, f"the Newton iteration failed ({error}); "
                                "the previous estimate is kept", 0, t_begin), math.inf
        return self._result(goal, 0.5 * (covariance + covariance.T), status, message, iterations, t_begin), misfit

    def _stale(self, goal: np.ndarray) -> bool:
        """True when the whitening was made for a goal farther from ``goal`` than the covariance tolerance, or
        misses more than the newest observation (updates that ended before the Newton iteration, e.g. with the
        hand at rest after a failed update, leave it behind)."""
        if self._whitening is None or self._whitened_observations < self.observation_count - 1:
            return True
        distance = np.linalg.norm(goal - self.start_position)
        return bool(np.linalg.norm(goal - self._whitening_goal) > self.options.covariance_tolerance * max(distance, self.width))

    def _whitening_at(self, goal: np.ndarray) -> ObservationWhitening:
        """The whitening of the observations so far under the belief of the plan to a goal near ``goal``: the
        current one extended by the new observation, or rebuilt at ``goal`` when it is stale."""
        steps = np.flatnonzero(self._counts)
        whitening = self._whitening
        if self._stale(goal):
            prediction = self._prediction(goal, order=0)
            cov = prediction.cov
            if self._rho < 1.0:
                cov = corrected_covariance(cov, self._A, self._rho, prediction.mean, self._deviation_times, self.model.h,
                                           self.model.n)
            whitening = ObservationWhitening(cov, self._powers, 2 * self.model.n, steps,
                                             np.array([self._step_noise(i, cov) for i in steps]),
                                             self._fractions[steps] / self._counts[steps])
            self._whitening, self._whitening_goal = whitening, np.array(goal, dtype=float)
        else:
            last = steps[-1]
            noise, fraction = self._step_noise(last, whitening.cov), self._fractions[last] / self._counts[last]
            if len(whitening.steps) == len(steps):
                whitening.redo_last(noise, fraction)
            else:
                whitening.append(last, noise, fraction)
        self._whitened_observations = self.observation_count
        return whitening

    def _step_noise(self, i: int, cov: np.ndarray) -> np.ndarray:
        """Noise covariance (2n, 2n) of the averaged observation of step i: R / m_i + f̄² Q_i, f̄ the mean
        fraction of a step its observations come after t_i, Q_i = Sigma_{i+1} - A Sigma_i A^T the motor noise
        of step i (:mod:`comanip.estimation.observation_whitening`)."""
        m, count = 2 * self.model.n, self._counts[i]
        mean_fraction = self._fractions[i] / count
        noise = self._R / count
        if mean_fraction > 0 and i < self.model.H:
            A = self._powers[1]
            noise = noise + mean_fraction**2 * (cov[i + 1] - A @ cov[i] @ A.T)[:m, :m]
        return noise

    def _result(self, goal, covariance, status: Status, message: str, iterations: int, t_begin: float) -> GoalEstimate:
        model, n = self.model, self.model.n
        prediction = self._prediction(goal, order=0)
        before, fraction = _grid_position(self._last_time, model.h, model.H)
        predicted = (1 - fraction) * prediction.mean[before, :2 * n] + fraction * prediction.mean[min(before + 1, model.H), :2 * n]
        plan = Plan(success=status in CONVERGED, status=status, message=message, objective=prediction.objective,
                    solve_time=time.perf_counter() - t_begin, iterations=iterations, t=model.h * np.arange(model.H + 1),
                    mean=prediction.mean, cov=prediction.cov, torque=prediction.torque, ee_mean=prediction.mean[:, :n].copy(),
                    ee_cov=prediction.cov[:, :n, :n].copy(), ee_velocity=prediction.mean[:, n:2 * n].copy(),
                    start=self.start.copy(), goal=np.array(goal, dtype=float), width=self.width, model_name=model.name)
        return GoalEstimate.of(plan, t_obs=self._last_time, observed_step=before,
                               observed_state=self._last_observation.copy(),
                               observation_residual=predicted - self._last_observation, prior_goal=self.prior_goal,
                               method="online", goal_covariance=np.array(covariance, dtype=float))

    def _prediction(self, goal, *, order: int = 1, covariance: bool = True) -> ReachPrediction:
        """The plan from the start to ``goal`` (:meth:`ReachFamily.prediction`), or holding still for a goal at
        the start (the plan there: zero torque, no noise)."""
        if np.linalg.norm(np.asarray(goal) - self.start_position) == 0.0:
            model = self.model
            H, nx, d = model.H, model.state_size, model.d
            return ReachPrediction(mean=np.tile(self.start, (H + 1, 1)), cov=np.zeros((H + 1, nx, nx)),
                                   torque=np.zeros((H, model.n)), objective=0.0, mean_jacobian=np.zeros((H + 1, nx, d)),
                                   direction=np.eye(d)[0], curvature=np.zeros((H + 1, nx // model.n)),
                                   mixed=np.zeros((H + 1, nx // model.n)))
        return self.family.prediction(self.start_position, goal, order=order, covariance=covariance)


def _grid_position(time_s: float, h: float, H: int) -> tuple[int, float]:
    """Where time_s (s, ≥ 0) falls on the grid of step h (s): the step i ≤ H at or before it and the fraction
    of a step (in [0, 1]) it lies after t_i; times at or after the horizon H·h read as (H, 0)."""
    grid = time_s / h
    before = min(H, int(math.floor(grid * (1 + 1e-9))))
    return before, (0.0 if before == H else min(max(grid - before, 0.0), 1.0))
