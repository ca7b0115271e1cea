"""A cold starting goal for the estimator: along the observed direction, the goal whose plan meets the observation.

Newton's method on the regret (:mod:`comanip.estimation.one_shot.regret_newton`) converges from near the answer, but
far from it the regret is flat (the expected reward underflows) and has other stationary points. Fitting a
minimum-jerk reach to the observation is no help early in a reach: the model's first steps accelerate at an
almost constant rate, which a minimum-jerk profile (zero initial acceleration) only matches with an
infinitely long movement (on the Cartesian preset at 0.165 s the fitted goal lay 2–60 reach lengths away).

So the model answers itself: goals are tried on the ray from the observed hand position x_o along its
velocity (for a point mass starting at rest, the very line of the reach) at distances D in
[D_min, D_max], and each is scored by the log-likelihood of the observed state under its plan's belief
(:func:`comanip.estimation.observation.prefix_log_likelihoods`). A bounded Brent search in log D
(scipy) needs about a dozen plans, each warm-started from the nearest distance already tried.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import minimize_scalar

from comanip.estimation.observation import prefix_log_likelihoods
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner

_AT_REST = 1e-6
"""Below this speed (m/s) and displacement (m) the observation shows no movement to extrapolate."""


class TaskSpaceState(NamedTuple):
    """Where the hand is and how it moves."""

    position: np.ndarray
    """End-effector position (d,), m."""
    velocity: np.ndarray
    """J(q) qdot (d,), m/s."""


class FoundGoal(NamedTuple):
    """A goal found along the observed direction, with its plan."""

    goal: np.ndarray
    """(d,), m."""
    plan: Plan


def task_space_state(planner: Planner, state: np.ndarray) -> TaskSpaceState:
    """The end effector's position and velocity of a state [q; qdot; ...] (2n or nx,)."""
    n = planner.model.n
    x, J = (np.asarray(v) for v in planner.model.body.kinematics_function(state[:n]))
    return TaskSpaceState(x.ravel(), J @ state[n:2 * n])


def search_along_observed_direction(planner: Planner, start, observed, n_o: int, prior, width: float, R: np.ndarray,
                                    distances: tuple[float, float], step_jacobians, remaining_time) -> FoundGoal | None:
    """The goal x_o + D u, u the observed direction, whose plan makes the observed state most likely.

    With a prior (a :class:`GoalPrior`) the score is the posterior: the log-likelihood plus log N(g; g_bar, P0),
    so where the observation says little about the distance (early in a slow reach) the prior decides it.

    Args:
        planner: the model's planner. start, observed: states (2n,). n_o: observed step.
        prior: the :class:`GoalPrior`, or None. width: goal width (m). R: observation-noise floor (2n, 2n).
        distances: (D_min, D_max), m, the range searched beyond the observed hand position.
        step_jacobians: the body's linearised step function (for the belief's likelihood).
        remaining_time: () -> seconds left (None: no budget), handed to each plan.

    Returns:
        (goal (d,), its plan), or None when the observation shows no movement (no direction to search).
    """
    x_start, _ = task_space_state(planner, start)
    x_obs, v_obs = task_space_state(planner, observed)
    if np.linalg.norm(v_obs) > _AT_REST:
        direction = v_obs / np.linalg.norm(v_obs)
    elif np.linalg.norm(x_obs - x_start) > _AT_REST:
        direction = (x_obs - x_start) / np.linalg.norm(x_obs - x_start)
    else:
        return None
    tried: dict[float, Plan] = {}

    def plan_at(log_distance: float) -> Plan:
        warm = tried[min(tried, key=lambda k: abs(k - log_distance))] if tried else None
        tried[log_distance] = planner.solve(start, x_obs + np.exp(log_distance) * direction, width,
                                            warm_start=warm, max_wall_time=remaining_time())
        return tried[log_distance]

    def misfit(log_distance: float) -> float:
        plan = plan_at(log_distance)
        score = -float(prefix_log_likelihoods(plan, observed[None, :], np.array([n_o]), R, step_jacobians)[-1])
        if prior is not None:
            score += 0.5 * (plan.goal - prior.mean) @ np.linalg.solve(prior.covariance, plan.goal - prior.mean)
        return score

    low, high = np.log(distances[0]), np.log(distances[1])
    best = minimize_scalar(misfit, bounds=(low, high), method="bounded", options={"xatol": 0.02})
    plan = tried[best.x] if best.x in tried else plan_at(best.x)
    return FoundGoal(plan.goal, plan)
