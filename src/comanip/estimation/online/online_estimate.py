"""What one update of the online estimator answers (:class:`OnlineEstimate`): the goal and its covariance, where
the hand will be (the forecast and its path, what a robot follows), and how the estimate was made.

Not a :class:`~comanip.Plan`: an online estimate predicts the rest of the person's movement from the hand's state
now, not a plan from the reach's start; the model's whole reach at the estimate's timing is one of its fields
(``timed_reach``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, fields
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from comanip.estimation.estimate_status import ESTIMATED
from comanip.estimation.forecast.hand_forecast import ForecastPoint, HandForecast

if TYPE_CHECKING:
    from comanip.estimation.model_reaches.reach_timing import TimedPlan


@dataclass(frozen=True)
class OnlineEstimate:
    """The estimate after the latest observation. Shapes: d task dimensions, n = d degrees of freedom (a point
    mass), nx state entries, K + 1 path times."""

    goal: np.ndarray
    """g_hat (d,), m: the goal a robot follows (smoothed, :attr:`unsmoothed_goal` the explanation's)."""
    goal_covariance: np.ndarray
    """Covariance of ``goal`` (d, d), m²: the explanation's (the inverse Hessian of the MAP goal, its spread along the
    reach from a quadrature early on, :mod:`comanip.estimation.online.online_estimator`), scaled by what is known
    of the person, plus the smoothed goal's offset from the explanation's."""
    status: str
    """Why the estimate is what it is: ``solved`` (the model explains the hand), ``people_model``,
    ``uninformative`` (the prior: the hand has not left its start, or nothing explains it), ``failed``, ...
    (:class:`~comanip.optim.Status`, :class:`~comanip.estimation.EstimateStatus`)."""
    message: str
    """Which explanation gave the estimate, and why those asked before it did not."""
    t_obs: float
    """Time of the latest observation after the reach's start (s)."""
    path: ForecastPoint
    """Where the hand will be from ``t_obs`` on: the forecast's grid up to ``OnlineOptions.forecast_horizon`` s ahead
    (times (K+1,) s, positions (K+1, d) m, velocities (K+1, d) m/s, covariances (K+1, d, d) m²); before the first
    observation the model's reach from the start. What the node publishes on its path topic."""
    forecast: HandForecast | None
    """The forecast of the rest of the reach from the hand's state at ``t_obs``
    (:class:`~comanip.estimation.forecast.hand_forecast.HandForecast`: ``forecast.at(t)`` gives the hand's mean
    position, velocity and covariance at any time t); None before the first observation."""
    timed_reach: "TimedPlan"
    """The model's whole reach from the start to g_hat, played at the estimate's timing
    (:func:`~comanip.estimation.model_reaches.reach_timing.timed_plan`): what the forecast continues from the hand."""
    observed_state: np.ndarray
    """The latest observed state [position; velocity] (2n,), m and m/s (zeros before any observation)."""
    observation_residual: np.ndarray
    """The timed reach's [q; qdot] at ``t_obs`` minus the observed state (2n,)."""
    prior_goal: np.ndarray
    """The prior's mean goal (d,), m."""
    unsmoothed_goal: np.ndarray
    """The goal the explanation gave (d,), m, before the smoothing that gives ``goal``
    (``OnlineOptions.goal_smoothing``, :mod:`comanip.estimation.calibration.goal_smoothing`); ``goal`` without it."""
    unsmoothed_goal_covariance: np.ndarray
    """That goal's covariance (d, d), m²."""
    start: np.ndarray
    """The reach's start state (nx,): position (n,) m, at rest."""
    width: float
    """Goal width w (m) of the reach the estimator's model plans."""
    model_name: str
    """The estimator's model."""
    solve_time: float
    """Wall time of the update (s)."""
    iterations: int
    """Newton iterations of the explanation's solve (0 where none was solved)."""

    @property
    def success(self) -> bool:
        """True when the estimate says where the hand heads (status in ``ESTIMATED``): not the prior, not failed."""
        return self.status in ESTIMATED

    @property
    def reach_distance(self) -> float:
        """D (m): from the reach's start to g_hat."""
        return float(np.linalg.norm(self.start[:len(self.goal)] - self.goal))

    def to_dict(self) -> dict:
        """JSON-ready dictionary (arrays as nested lists): the goal, its covariance, the status and message, the path
        (``t_s``, ``position_m``, ``velocity_m_s``, ``covariance_m2``), the forecast as its stop, pace and phase, the
        timed reach as its times and mean states, and the rest of the fields."""
        out = {"success": self.success}
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "path":
                value = {"t_s": value.t, "position_m": value.position, "velocity_m_s": value.velocity,
                         "covariance_m2": value.covariance}
            elif item.name == "forecast":
                value = None if value is None else {"stop_time_s": value.stop_time, "pace": value.pace, "phase_s": value.phase}
            elif item.name == "timed_reach":
                value = {"t": value.t, "mean": value.mean}
            out[item.name] = value
        return _listed(out)

    def save_json(self, path: str | Path) -> Path:
        """``to_dict`` written to ``path`` (JSON); the path."""
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path


def _listed(value):
    """``value`` with every array (and every array inside a dict) as nested lists, every str enum as its value."""
    if isinstance(value, dict):
        return {key: _listed(item) for key, item in value.items()}
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, str):
        return str(value.value) if hasattr(value, "value") else value
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    return value
