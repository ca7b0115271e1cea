"""The result of a goal estimate from one observed state: a :class:`~comanip.Plan` of the predicted reach, and how it
was estimated (the online estimator's is :class:`~comanip.estimation.online.online_estimate.OnlineEstimate`)."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from comanip.planning.plan import Plan


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
    """'regret' or 'paper' (eq. 11 as printed)."""
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
    plus the prior's)."""
    plan_status: str | None = None
    """For an 'uninformative' estimate (observation at step 0): the status of the plan to the prior goal."""

    @property
    def estimated_goal(self) -> np.ndarray:
        """g_hat (d,), m: the plan's goal."""
        return self.goal

    @classmethod
    def of(cls, plan: Plan, **details) -> "GoalEstimate":
        """The estimate whose predicted reach is ``plan``, with ``details`` (the fields above)."""
        return cls(**{f.name: getattr(plan, f.name) for f in fields(Plan)}, **details)
