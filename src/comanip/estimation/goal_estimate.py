"""The result of a goal estimate: a :class:`~comanip.Plan` of the predicted reach, and how it was estimated."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING

import numpy as np

from comanip.planning.plan import Plan

if TYPE_CHECKING:
    from comanip.estimation.forecast.hand_forecast import HandForecast
    from comanip.estimation.model_reaches.reach_timing import TimedPlan


@dataclass
class GoalEstimate(Plan):
    """A goal estimate: the predicted reach from the start through the observation to the estimated goal
    g_hat (the :class:`Plan` fields; ``goal`` is g_hat, so it plots and exports like any plan), and how it
    was made. Shapes: nx state entries, d task dimensions, H steps, n degrees of freedom."""

    t_obs: float = 0.0
    """Time of the observation after the start (s)."""
    observed_step: int = 0
    """The step n_o of the predicted reach at or before t_obs that it was matched to (floor(t_obs / h) for a
    reach from t = 0 at the model's pace)."""
    observed_state: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """The observed state s_o (nx,)."""
    observation_residual: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """Predicted mean at n_o minus the observed state (nx,): zero in the rows the estimate holds."""
    prior_goal: np.ndarray | None = None
    """g_bar (d,), m, of the regulariser; None without one."""
    method: str = "regret"
    """'regret', 'paper' (eq. 11 as printed) or 'online' (:class:`comanip.estimation.OnlineGoalEstimator`)."""
    multipliers: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """Multipliers of the observation constraint (one per observed row); a later estimate at a step like
    this one's starts from them."""
    regret: float | None = None
    """Jc(g_hat) - V*(g_hat), J units ('regret' method; None for 'paper')."""
    residual: float | None = None
    """max |F| of the regret's first-order conditions at the estimate ('regret' method)."""
    unconstrained_torque: np.ndarray | None = None
    """The plan to the estimated goal, not held to the observation (H, n) ('regret' method)."""
    goal_covariance: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    """Covariance of the estimated goal (d, d), m²: the Laplace approximation of the posterior ('regret' and
    'paper': the Gauss–Newton curvature of the observation's negative log-likelihood under the model's belief,
    plus the prior's; 'online': the inverse Hessian, its spread along the reach from a quadrature early on,
    :mod:`comanip.estimation.online.online_estimator`)."""
    unsmoothed_goal: np.ndarray | None = None
    """'online': the goal the explanation gave (d,), m, before the smoothing that gives ``goal``
    (``OnlineOptions.goal_smoothing``, :mod:`comanip.estimation.calibration.goal_smoothing`); the same as ``goal`` without it."""
    unsmoothed_goal_covariance: np.ndarray | None = None
    """'online': that goal's covariance (d, d), m²; ``goal_covariance`` adds the smoothed goal's offset from it."""
    forecast: "HandForecast | None" = None
    """'online': the forecast of the rest of the reach from the hand's state at t_obs
    (:class:`~comanip.estimation.forecast.hand_forecast.HandForecast`; ``forecast.at(t)`` gives the hand's mean position,
    velocity and covariance at any time t). The estimate's plan fields (``t``, ``mean``, ``ee_mean``, ``ee_cov``,
    ``ee_velocity``) are its grid, from t_obs on; before the first observation (None) they are the model's reach
    from the start."""
    timed_reach: "TimedPlan | None" = None
    """'online': the model's whole reach from the start to g_hat, played at the estimate's timing
    (:func:`~comanip.estimation.model_reaches.reach_timing.timed_plan`): what the forecast continues from the hand."""
    plan_status: str | None = None
    """For an 'uninformative' estimate (observation at step 0): the status of the plan to the prior goal."""

    @property
    def reach_distance(self) -> float:
        """D (m): from the reach's start to g_hat (the path of an online estimate starts at the hand now)."""
        if self.forecast is None:
            return super().reach_distance
        return float(np.linalg.norm(self.start[:self.forecast.d] - self.goal))

    @property
    def estimated_goal(self) -> np.ndarray:
        """g_hat (d,), m: the plan's goal."""
        return self.goal

    def to_dict(self) -> dict:
        """JSON-ready dictionary (arrays as nested lists); the forecast as its stop, pace and phase (its grid is
        the plan fields'), the timed reach as its times and mean states."""
        out = super().to_dict()
        if self.timed_reach is not None:
            out["timed_reach"] = {"t": self.timed_reach.t.tolist(), "mean": self.timed_reach.mean.tolist()}
        if self.forecast is not None:
            out["forecast"] = {"stop_time_s": self.forecast.stop_time, "pace": self.forecast.pace,
                               "phase_s": self.forecast.phase}
        return out

    @classmethod
    def of(cls, plan: Plan, **details) -> "GoalEstimate":
        """The estimate whose predicted reach is ``plan``, with ``details`` (the fields above)."""
        return cls(**{f.name: getattr(plan, f.name) for f in fields(Plan)}, **details)
