"""How the online estimator works: :class:`OnlineOptions`, and the options for a person who corrects."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_count, as_positive
from comanip.estimation.calibration.goal_smoothing import GoalSmoothing
from comanip.estimation.observation import OBSERVATION_STD, observation_covariance
from comanip.estimation.people.people_model import PeopleModel


TIMINGS = ("estimated", "paced", "model")
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
    whitening when the estimate moved; ``OnlineEstimate.iterations`` counts them all)."""
    step_fraction: float = 0.5
    """Largest goal step, as a fraction of the distance from the start to the current goal (at least one width)."""
    covariance_tolerance: float = 0.05
    """The belief covariance that weighs the observations is the plan's to a goal within this fraction of the
    distance (start to goal) of the estimate; it is recomputed when the estimate moves farther."""
    correction_time: float | None = None
    """Time constant (s) with which the person corrects a deviation from their plan
    (:mod:`comanip.estimation.online.corrected_deviation`); None: the plan's open-loop belief, a deviation persists.
    The ``correcting`` and ``sync_robot`` descriptions (:mod:`comanip.estimation.streaming.online_settings`) use 0.3 s."""
    deviation_time: float = 0.0
    """With a correction time: the person strays from the plan by about this many seconds (s) of their motion,
    in any direction (ahead, behind, across; :mod:`comanip.estimation.online.corrected_deviation`); 0: only motor noise.
    The ``correcting`` and ``sync_robot`` descriptions use 0.15 s."""
    led_axes: tuple[int, ...] = ()
    """Axes (indices into the hand position, 0..d-1) along which someone else moves the hand, e.g. the robot
    that leads z in the sync scenario: there the observed motion is partly theirs, not the person's reach, and
    strays from the person's plan by ``led_deviation_time`` seconds of its motion instead of
    ``deviation_time`` (it counts for less while the hand moves; at rest it still pins the goal). Needs a
    correction time. Empty: every axis is the person's."""
    led_deviation_time: float = 0.3
    """sigma_t (s) along the ``led_axes`` (:mod:`comanip.estimation.online.corrected_deviation`)."""
    led_from: float = 0.0
    """Time (s since the reach's start) from which someone else leads the ``led_axes``; before it they are the
    person's (the sync robot leads z from t_o)."""
    covariance_scale: float = 1.0
    """The reported goal covariance is the Laplace (and quadrature) one times this factor (the estimate itself
    is unchanged). 1: as computed, calibrated for the open-loop belief. Under a correction time most
    ellipsoids are too wide and some far too narrow (docs/results/calibration.md); the sync robot's belief
    uses 3 (the ``sync_robot`` description, :mod:`comanip.estimation.streaming.online_settings`)."""

    timing: str = "estimated"
    """"model": the reach starts at t = 0 and moves at the model's pace (the estimate above, exact for the
    model's own reaches). "estimated": that estimate while the model at its own pace explains the observations
    (whitened misfit at most ``mismatch_threshold``); from the first update on which it does not, the model
    fitted to recorded people (:mod:`comanip.estimation.people.people_model`), status ``people_model``. "paced": as
    "estimated", the model's timing also rejected by a fit of its reach at a free pace and onset, and that reach
    at the person's own pace and onset (:mod:`comanip.estimation.model_reaches.paced_model`) asked before the people model,
    where it explains the hand (misfit at most ``paced_threshold``): for hands that move as the model does at
    another pace. Goals from either are combined with the prior."""
    mismatch_threshold: float = 9.0
    """With ``timing="estimated"`` or ``"paced"``: the largest mean squared whitened residual (per observed number) at which
    the model at its own pace still explains the observations (about 1 for the model's own reaches)."""
    people_model: PeopleModel | None = None
    """With ``timing="estimated"`` or ``"paced"``: the model of people's movements (:class:`comanip.estimation.people.people_model.PeopleModel`,
    e.g. fitted to your own recordings); None: the one that ships with comanip for the kind of movement the
    reaching model makes (``arm``, fitted to arm reaches, for a 3-D model; ``mouse`` for a 2-D one). A model
    fitted to mouse movements is refused for a 3-D reach."""
    paced_threshold: float = 0.05
    """With ``timing="paced"``: the largest misfit (chi² per observed number, :mod:`comanip.estimation.model_reaches.profile_fit`)
    at which the model's reach at the person's pace explains the observations."""
    forecast_horizon: float | None = None
    """How far ahead (s) of each update the estimate's path reaches: its plan fields (``t``, ``mean``, ``ee_mean``,
    ...; the path a robot or the ROS node's path topic follows) hold the forecast from the update to this many seconds
    on, where the forecast's last point is (the forecast itself, ``estimate.forecast.at``, still answers any time);
    None: to the forecast's stop."""
    goal_smoothing: GoalSmoothing | None = GoalSmoothing()
    """How the estimate's ``goal`` is smoothed over updates for a robot to follow
    (:mod:`comanip.estimation.calibration.goal_smoothing`; the explanation's own goal stays as ``unsmoothed_goal``); None: not
    smoothed."""

    def __post_init__(self):
        observation_covariance(self.observation_std, 1)
        if self.goal_smoothing is not None and not isinstance(self.goal_smoothing, GoalSmoothing):
            raise ValueError(f"goal_smoothing must be a GoalSmoothing or None, got {type(self.goal_smoothing).__name__}")
        if self.forecast_horizon is not None:
            as_positive("forecast_horizon", self.forecast_horizon, "s ahead (or None: to the forecast's stop)")
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

