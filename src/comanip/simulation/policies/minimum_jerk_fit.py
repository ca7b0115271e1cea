"""(c) Minimum-jerk fit (Flash & Hogan 1985): the observed prefix of the reach is fitted by a rest-to-rest
minimum-jerk reach from the start, x(t) = x_0 + (g - x_0) sigma(t / T) with
sigma(s) = 10 s³ - 15 s⁴ + 6 s⁵ (s clipped to [0, 1]), whose goal g (3,) m and duration T (s) are unknown.

Early in a reach only (g - x_0) / T³ is visible, so the fit is a MAP estimate: positions with noise std
``observation_std`` (m) and a Gaussian prior on g about g_bar with std ``prior_std`` (m). For a fixed T the
goal is a ridge regression in closed form; T is found by a bounded scalar search over [T_min, T_max].
The rest motion is the fitted reach from the current time on. Re-predicted every update_interval.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from comanip.arguments import as_positive
from comanip.planning.starts.initial_guess import minimum_jerk
from comanip.simulation.policies.protocol import PolicyContext, Prediction


@dataclass(frozen=True)
class MinimumJerkFit:
    """A fitted minimum-jerk reach: goal (3,) m, duration (s), and the fit's objective (dimensionless)."""

    goal: np.ndarray
    duration: float
    objective: float


def fit_minimum_jerk(start, times, positions, prior_goal, *, observation_std: float = 1e-3, prior_std: float = 0.1,
                     duration_bounds: tuple[float, float] = (0.3, 3.0)) -> MinimumJerkFit:
    """The MAP minimum-jerk reach (module docstring) from start (d,) m at time 0 through positions (K, d) m
    observed at times (K,) s, with the prior goal (d,) m."""
    start, prior_goal = np.asarray(start, dtype=float), np.asarray(prior_goal, dtype=float)
    times, positions = np.asarray(times, dtype=float), np.asarray(positions, dtype=float)
    if times.ndim != 1 or positions.shape != (len(times), len(start)):
        raise ValueError(f"times must be (K,) and positions (K, {len(start)}), got {times.shape} and {positions.shape}")
    as_positive("observation_std", observation_std, "m")
    as_positive("prior_std", prior_std, "m")
    low, high = (as_positive(f"duration_bounds[{k}]", v, "s") for k, v in enumerate(duration_bounds))
    if low >= high:
        raise ValueError(f"duration_bounds must be (T_min, T_max) with 0 < T_min < T_max (s), got {duration_bounds!r}")
    offsets, prior_offset = positions - start, prior_goal - start
    a, b = 1.0 / observation_std**2, 1.0 / prior_std**2

    def solve(duration: float) -> MinimumJerkFit:
        sigma = minimum_jerk(0.0, 0.0, 1.0, duration, times)[0][:, 0]        # the unit profile (K,)
        offset = (a * sigma @ offsets + b * prior_offset) / (a * sigma @ sigma + b)
        residual = offsets - np.outer(sigma, offset)
        return MinimumJerkFit(start + offset, duration, float(a * np.sum(residual**2) + b * np.sum((offset - prior_offset) ** 2)))

    grid = np.geomspace(low, high, 25)
    k = int(np.argmin([solve(T).objective for T in grid]))
    bracket = (grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)])
    best = minimize_scalar(lambda T: solve(T).objective, bounds=bracket, method="bounded", options={"xatol": 1e-4})
    return solve(float(best.x))


class MinimumJerkPolicy:
    """Fits the observed prefix (sampled every ``sample_interval``) at every update."""

    name = "minimum-jerk"
    leads_height = True

    def __init__(self, context: PolicyContext, sample_interval: float = 0.005, observation_std: float = 1e-3,
                 prior_std: float = 0.1):
        self.context = context
        self.update_interval = context.update_interval
        self.sample_interval, self.observation_std, self.prior_std = sample_interval, observation_std, prior_std
        self.times: list[float] = []
        self.positions: list[np.ndarray] = []
        self.fit: MinimumJerkFit | None = None

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        if not self.times or t >= self.times[-1] + self.sample_interval - 1e-9:
            self.times.append(t)
            self.positions.append(np.array(position, dtype=float))

    def predict(self, t: float) -> Prediction:
        c = self.context
        start = c.start[:3]
        self.fit = fit_minimum_jerk(start, self.times, np.array(self.positions), c.prior_goal,
                                    observation_std=self.observation_std, prior_std=self.prior_std)
        position, velocity, _ = minimum_jerk(start, np.zeros(3), self.fit.goal, self.fit.duration, c.rest_times(t))
        return Prediction(self.fit.goal.copy(), c.rest_from(t, position, velocity))
