"""The online estimator's MAP goal for one update (:class:`~comanip.estimation.online.online_estimator.OnlineGoalEstimator`).

The observations averaged per grid step, y_s at the steps s (S,) with interpolation weights of the grid's
means (S, H+1), are compared with the mean of the plan to a goal g (:class:`~comanip.estimation.model_reaches.reach_family.ReachFamily`),
whitened under a fixed belief (:class:`~comanip.estimation.online.observation_whitening.ObservationWhitening`):

    -log p(g) = ½ |L⁻¹ (y - mu(g))|² + ½ (g - g_bar)ᵀ P0⁻¹ (g - g_bar) + const.

:class:`MapProblem` gives its value, gradient and Hessian (Newton's, or the Gauss–Newton matrix where that is not
positive definite), a cold start, and the spread of the distance along the reach; :class:`MapNewton` minimises
it with the one Newton iteration (:func:`comanip.optim.newton_loop.newton_iterate`): a step no longer than
``step_fraction`` of the goal's distance, halved until -log p does not rise (:func:`comanip.optim.backtrack`),
converged once the Newton decrement falls below ``DECREMENT``, and settled by taking that last Newton step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Callable

import numpy as np

from comanip.estimation.estimate_status import EstimateStatus
from comanip.estimation.online.observation_whitening import ObservationWhitening
from comanip.estimation.model_reaches.reach_family import ReachFamily, ReachPrediction
from comanip.optim import CholeskyFactor, SolverResult, Status, backtrack, shifted_cholesky
from comanip.optim.newton_loop import NewtonMethod, Stop, newton_iterate

MOVEMENT_SIGMAS = 3.0
"""Observed speed and displacement beyond this many noise standard deviations count as movement."""
SKEWED, QUADRATURE_POINTS = 0.05, 80
"""Relative std along the reach above which the goal's variance there comes from a quadrature, and its points."""
BACKTRACKS = 12
"""Halvings of a Newton step before the iteration gives up."""
DECREMENT = 1e-6
"""Newton decrement (the decrease of -log p the step predicts, nats) below which an update has converged."""
ACCEPTABLE_DECREMENT = 1e-6
"""... and, relative to -log p, below which a step that no line search can lower counts as converged (rounding)."""


@dataclass(frozen=True)
class MapTerms:
    """-log p at a goal and its derivatives."""

    objective: float
    hessian: np.ndarray
    """Newton's Hessian (d, d), symmetrised."""
    gauss_newton: np.ndarray
    """The Gauss–Newton matrix (d, d), positive definite."""
    descent: np.ndarray
    """Minus the gradient (d,)."""

    @cached_property
    def factor(self) -> CholeskyFactor:
        """The Cholesky factor of the Hessian when it is positive definite, else of the Gauss–Newton matrix.
        Raises numpy's LinAlgError when neither is."""
        factor = shifted_cholesky(self.hessian, (0.0,), lower=True)
        if factor is None:
            factor = shifted_cholesky(self.gauss_newton, (0.0,), lower=True)
            if factor is None:
                raise np.linalg.LinAlgError("the Gauss–Newton matrix is not positive definite")
        return factor

    @cached_property
    def step(self) -> np.ndarray:
        """The Newton step (d,) m, with :attr:`factor`'s matrix."""
        return self.factor.solve(self.descent)

    @property
    def decrement(self) -> float:
        """The decrease of -log p the Newton step predicts (nats)."""
        return 0.5 * float(self.step @ self.descent)

    def covariance(self) -> np.ndarray:
        """The Laplace covariance: the inverse of :attr:`factor`'s matrix (d, d), m²."""
        return self.factor.inverse()


@dataclass
class MapProblem:
    """One update's MAP problem (module docstring)."""

    family: ReachFamily
    predict: Callable[[np.ndarray], ReachPrediction]
    """goal (d,) m -> the plan to it with its mean's derivatives in the goal (order 2, no covariance)."""
    start_position: np.ndarray
    """Hand at the start x_0 (d,), m."""
    prior_mean: np.ndarray
    """g_bar (d,), m."""
    prior_precision: np.ndarray
    """P0⁻¹ (d, d), 1/m²."""
    steps: np.ndarray
    """Grid steps with observations (S,)."""
    observed: np.ndarray
    """Their averaged observations (S, 2n): positions m, velocities m/s."""
    weights: np.ndarray
    """Interpolation weights of the grid's means (S, H+1)."""

    def __post_init__(self):
        self.m = self.observed.shape[1]
        self._predicted: tuple[bytes, ReachPrediction] | None = None    # the last goal's prediction (rounds share it)

    def prediction(self, goal: np.ndarray) -> ReachPrediction:
        key = goal.tobytes()
        if self._predicted is None or self._predicted[0] != key:
            self._predicted = key, self.predict(goal)
        return self._predicted[1]

    def terms(self, whitening: ObservationWhitening, goal: np.ndarray) -> MapTerms:
        """-log p and its derivatives at ``goal`` under ``whitening``."""
        m, d = self.m, len(goal)
        prediction = self.prediction(goal)
        H1, nx = prediction.mean.shape
        grid = np.concatenate([prediction.mean[:, :m, None], prediction.mean_jacobian[:, :m]], axis=2)
        columns = (self.weights @ grid.reshape(H1, -1)).reshape(len(self.steps), m, 1 + d)
        columns[:, :, 0] = self.observed - columns[:, :, 0]
        flat = whitening.apply(columns).reshape(-1, 1 + d)
        residual, G = flat[:, 0], flat[:, 1:]
        offset = goal - self.prior_mean
        objective = 0.5 * float(residual @ residual + offset @ self.prior_precision @ offset)
        gauss_newton = G.T @ G + self.prior_precision
        # Newton's Hessian adds -sum_j e_j (L^-1 d²mu/dg²)_j, the residuals pulled back onto the grid's means
        z = np.zeros((H1, nx))
        z[:, :m] = self.weights.T @ whitening.transpose_apply(residual)
        newton = gauss_newton - prediction.hessian_contraction(z)
        return MapTerms(objective, 0.5 * (newton + newton.T), gauss_newton, G.T @ residual - self.prior_precision @ offset)

    def misfit(self, whitening: ObservationWhitening, goal: np.ndarray) -> float:
        """Mean squared whitened residual of the observations at ``goal``, per observed number: about 1 where
        the model at its own pace explains them."""
        predicted = self.weights @ self.prediction(goal).mean[:, :self.m]
        residual = whitening.apply((self.observed - predicted)[:, :, None]).ravel()
        return float(residual @ residual) / residual.size

    def projected(self, goal: np.ndarray) -> np.ndarray:
        """The goal moved into the family's range of distances from the start."""
        offset = goal - self.start_position
        D = math.sqrt(float(offset @ offset))
        low, high = self.family.distances[0], self.family.distances[-1]
        if D == 0:
            return self.start_position + low * np.eye(len(goal))[0]
        if low <= D <= high:
            return goal
        return self.start_position + offset * (min(max(D, low), high) / D)

    def at_range_end(self, goal: np.ndarray) -> bool:
        """Whether ``goal`` sits at the largest distance the family covers."""
        return bool(np.linalg.norm(goal - self.start_position) >= self.family.distances[-1] * (1 - 1e-9))

    def range_message(self) -> str:
        return (f"the estimate sits at the largest distance the reach family covers ({self.family.distances[-1]:g} m): "
                "the observations point farther than the model's plans reach")

    def distance_spread(self, goal: np.ndarray, covariance: np.ndarray, whitening: ObservationWhitening) -> np.ndarray:
        """The covariance with its variance along the reach replaced by the posterior's along the line through
        the start and ``goal`` (1-D quadrature on a grid of distances), and the spread across it scaled by the
        root mean square distance over D_hat, where the Laplace approximation's relative std along the reach
        exceeds :data:`SKEWED`: early in a reach the distance's posterior has a long tail towards far goals
        that the curvature at the mode does not see."""
        offset = goal - self.start_position
        D = float(np.linalg.norm(offset))
        u = offset / D
        variance = float(u @ covariance @ u)
        spread = math.sqrt(variance) / D
        if spread < SKEWED:
            return covariance
        family = self.family
        low = max(math.log(D) - 6 * spread, math.log(family.distances[0]))
        high = min(math.log(D) + 6 * spread, math.log(family.distances[-1]))
        if high - low < 1e-6:
            return covariance
        distances = np.exp(np.linspace(low, high, QUADRATURE_POINTS))
        n, m, M = family.model.n, self.m, len(distances)
        along = self.weights @ family.along(distances)[:, :, :m // n]               # (M, S, 2): position, velocity
        means = (along[:, :, :, None] * u).reshape(M, len(self.steps), m)
        means[:, :, :n] += self.start_position
        whitened = whitening.matrix @ (self.observed[None] - means).reshape(M, -1).T
        goals = self.start_position + distances[:, None] * u
        offsets = goals - self.prior_mean
        energy = 0.5 * (np.sum(whitened**2, axis=0) + np.einsum("ki,ij,kj->k", offsets, self.prior_precision, offsets))
        weights = np.exp(-(energy - energy.min())) * np.gradient(distances)
        weights /= weights.sum()
        along = float(weights @ (distances - D) ** 2)
        # across the reach the direction's uncertainty spreads the goal in proportion to its distance
        across = np.eye(len(u)) - np.outer(u, u)
        stretch = math.sqrt(max(1.0, float(weights @ distances**2) / D**2))
        scale = across * stretch + np.outer(u, u)
        return scale @ covariance @ scale + max(0.0, along - variance) * np.outer(u, u)

    def cold_goal(self, latest: np.ndarray, observation_std: tuple[float, float], noise: np.ndarray) -> np.ndarray | None:
        """The best member of the family along the observed directions (latest velocity, latest displacement
        from the start, and the prior's direction), scored by the observations' likelihood with each step's
        error taken independently, plus the prior; None when no observation shows movement beyond its noise.

        Args:
            latest: the latest observation (2n,): position m, velocity m/s.
            observation_std: (position m, velocity m/s) standard deviations of one observation.
            noise: the averaged observations' noise covariances (S, 2n, 2n).
        """
        family = self.family
        n = family.model.n
        sigma_q, sigma_v = observation_std
        directions = []
        if np.linalg.norm(latest[n:]) > MOVEMENT_SIGMAS * sigma_v:
            directions.append(latest[n:] / np.linalg.norm(latest[n:]))
        displacement = latest[:n] - self.start_position
        if np.linalg.norm(displacement) > MOVEMENT_SIGMAS * sigma_q:
            directions.append(displacement / np.linalg.norm(displacement))
        if not directions:
            return None
        prior_offset = self.prior_mean - self.start_position
        if np.linalg.norm(prior_offset) > 0:
            directions.append(prior_offset / np.linalg.norm(prior_offset))
        m = self.m
        best, best_score = None, math.inf
        member_cov = family.member_cov[:, self.steps, :m, :m]
        # the members' means at the observations in their own frame: a_b (K, S) on the first axis of each block b
        along = self.weights @ family.member_along[:, :, :m // n]                        # (K, S, blocks)
        member_means = np.zeros(along.shape[:2] + (m,))
        member_means[:, :, ::n] = along
        observed = self.observed.copy()
        observed[:, :n] -= self.start_position
        factored = None                 # (noise in the member's frame, its members' inverses, log-determinants)
        for u in directions:
            goals = self.start_position + family.distances[:, None] * u
            T = family.frame(u)[:m, :m]
            r = observed @ T - member_means                                               # (K, S, m), member frame
            turned = T.T @ noise @ T            # the same for every direction where the noise is isotropic per block
            if factored is None or not np.allclose(turned, factored[0], rtol=0.0, atol=1e-12 * float(np.abs(noise).max())):
                S = member_cov + turned
                factored = turned, np.linalg.inv(S), np.linalg.slogdet(S)[1]
            solved = (factored[1] @ r[..., None])[..., 0]
            log_det = factored[2]
            offsets = goals - self.prior_mean
            scores = 0.5 * (np.sum(r * solved, axis=(1, 2)) + log_det.sum(axis=1)
                            + np.einsum("ki,ij,kj->k", offsets, self.prior_precision, offsets))
            k = int(np.argmin(scores))
            if scores[k] < best_score:
                best, best_score = goals[k], scores[k]
        return best


@dataclass
class MapState:
    """The MAP iteration's iterate: the goal (d,) m and -log p's terms there."""

    goal: np.ndarray
    terms: MapTerms
    iterations: int = 0


@dataclass
class MapNewton(NewtonMethod[MapState, np.ndarray]):
    """Newton's method on -log p under a fixed whitening (module docstring): the hooks of
    :func:`~comanip.optim.newton_loop.newton_iterate`."""

    problem: MapProblem
    whitening: ObservationWhitening
    tolerance: float
    """Goal step (m) below which the iteration has converged."""
    step_fraction: float
    """Longest step, a fraction of max(|g - x_0|, ``width``)."""
    width: float
    """Goal width w (m)."""

    def solve(self, goal: np.ndarray, max_iterations: int) -> SolverResult[np.ndarray, MapTerms]:
        """The MAP goal from ``goal``: x the goal (d,) m, fun -log p, local_model the :class:`MapTerms` at the last
        iterate (its :meth:`MapTerms.covariance` is the Laplace covariance). Raises numpy's LinAlgError when the
        Gauss–Newton matrix is singular."""
        goal = self.problem.projected(np.asarray(goal, dtype=float))
        state = MapState(goal, self.problem.terms(self.whitening, goal))
        return newton_iterate(self, state, max_iterations=max_iterations)

    def iterations(self, state: MapState) -> int:
        return state.iterations

    def begin(self, state: MapState) -> None:
        state.iterations += 1

    def converged(self, state: MapState) -> Stop | None:
        """The Newton step would lower -log p by less than DECREMENT, or is shorter than the tolerance."""
        step = state.terms.step
        if state.terms.decrement > DECREMENT and math.sqrt(float(step @ step)) > self.tolerance:
            return None
        return Stop(Status.SOLVED, f"converged in {state.iterations} Newton iterations")

    def settle(self, state: MapState, stop: Stop) -> Stop:
        """The last Newton step, taken whole (the terms stay those it was computed from); at the family's largest
        distance the estimate is not a solution."""
        state.goal = self.problem.projected(state.goal + state.terms.step)
        if self.problem.at_range_end(state.goal):
            return Stop(EstimateStatus.AT_RANGE_END, self.problem.range_message())
        return stop

    def direction(self, state: MapState) -> np.ndarray:
        step = state.terms.step
        offset = state.goal - self.problem.start_position
        limit = self.step_fraction * max(math.sqrt(float(offset @ offset)), self.width)
        length = math.sqrt(float(step @ step))
        return step * (limit / length) if length > limit else step

    def globalise(self, state: MapState, step: np.ndarray) -> bool:
        """Halve the step until -log p does not rise (to rounding)."""
        objective = state.terms.objective
        rounding = 1e-12 * abs(objective)

        def attempt(alpha: float, bound: float) -> MapState | None:
            goal = self.problem.projected(state.goal + alpha * step)
            trial = MapState(goal, self.problem.terms(self.whitening, goal))
            return trial if trial.terms.objective <= bound + rounding else None

        accepted = backtrack(attempt, objective, 0.0, max_trials=BACKTRACKS).accepted
        if accepted is None:
            return False
        state.goal, state.terms = accepted.goal, accepted.terms
        return True

    def recover(self, state: MapState, step: np.ndarray) -> Stop:
        """No step lowers -log p: converged to rounding when the decrement is that small, else failed."""
        if self.problem.at_range_end(state.goal):
            return Stop(EstimateStatus.AT_RANGE_END, self.problem.range_message())
        decrement = state.terms.decrement
        if decrement <= ACCEPTABLE_DECREMENT * max(1.0, abs(state.terms.objective)):
            return Stop(Status.SOLVED_ACCEPTABLE, f"no Newton step lowers the objective any more (decrement {decrement:.2g})")
        return Stop(Status.FAILED, f"no Newton step lowers the objective, though it predicts a decrease of {decrement:.2g}")

    def result(self, state: MapState, stop: Stop) -> SolverResult[np.ndarray, MapTerms]:
        """The goal found; a budget run out with the goal at the family's largest distance is that range's end."""
        if stop.status == Status.MAX_ITERATIONS and self.problem.at_range_end(state.goal):
            stop = Stop(EstimateStatus.AT_RANGE_END, self.problem.range_message())
        return SolverResult(state.goal, state.terms.objective, stop.status, stop.message, state.iterations,
                            float(np.abs(state.terms.descent).max()), local_model=state.terms)

