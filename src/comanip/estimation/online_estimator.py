"""Continuous goal estimation: the goal of a reach in progress, revised with every observation (issue 12).

A person at rest at s_0 reaches for an unknown goal g; positions and velocities of their hand arrive one at a
time, at any times t_k ≥ 0. After each, :meth:`OnlineGoalEstimator.update` returns the maximum a posteriori
goal g_hat under the model and its covariance, with the model's predicted reach to g_hat:

    g_hat = argmin_g  ½ |L^-1 (y - mu(g))|² + ½ (g - g_bar)^T P0^-1 (g - g_bar)

where mu(g) stacks the plan's predicted mean [q; qdot] at the observation times (linearly interpolated
between grid steps), L is the factor of the observations' joint covariance under the plan's open-loop belief
plus the observation noise R (:mod:`comanip.estimation.observation_whitening`), and (g_bar, P0) the prior
(:mod:`comanip.estimation.goal_prior`). Every observation so far enters. The covariance is held at the
previous estimate's plan during an update (its dependence on g is left out of the objective, as in iteratively
reweighted least squares: an exact observation of a plan then gives back its goal), and the minimum is
found by Gauss–Newton steps warm-started from the previous estimate. The goal's covariance is the Laplace
approximation with the Gauss–Newton curvature, (G^T G + P0^-1)^-1, G = L^-1 d mu / d g.

The plans come from a :class:`~comanip.estimation.reach_family.ReachFamily` of the model, built once per model
and width: for a rotation-invariant point mass from rest, the plan to any goal is a 1-D reach turned onto its
direction, read from a spline over distance, together with d mu / d g. So an update needs no plan solve.
What is approximated: the predicted reach is the spline's, within ``family.interpolation_error`` (m, measured
at build time against real plans; about 1e-4 m or less on the paper presets) of the model's plan; an
observation between grid steps takes the mean interpolated linearly in time and the state error of the
nearest step. The first (cold) estimate starts from the best family member along the observed directions.

>>> estimator = OnlineGoalEstimator(comanip.presets.cartesian(), np.zeros(6))
>>> estimate = estimator.update(0.1, position, velocity)
>>> estimate.goal, estimate.goal_covariance, estimate.mean
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_count, as_positive, as_vector
from comanip.belief.propagation import linearised_step_function
from comanip.estimation.estimate import GoalEstimate
from comanip.estimation.goal_prior import prior_covariance
from comanip.estimation.observation import OBSERVATION_STD, observation_covariance
from comanip.estimation.observation_whitening import ObservationWhitening
from comanip.estimation.reach_family import ReachFamily, ReachPrediction
from comanip.estimation.shared import checked_model, estimation_planner
from comanip.model import ReachingModel
from comanip.optim import CONVERGED, Status
from comanip.planning.cache import ModelCache
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner


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
    """A Gauss–Newton goal step shorter than this (m) ends an update."""
    max_iterations: int = 20
    """Gauss–Newton iterations per update."""
    step_fraction: float = 0.5
    """Largest goal step, as a fraction of the distance from the start to the current goal (at least one width)."""

    def __post_init__(self):
        observation_covariance(self.observation_std, 1)
        low, high = (as_positive(f"family_distances[{k}]", v, "m") for k, v in enumerate(self.family_distances))
        if low >= high:
            raise ValueError(f"family_distances must be (D_min, D_max) with D_min < D_max (m), got {self.family_distances!r}")
        as_count("family_size", self.family_size, 4)
        as_positive("family_tolerance", self.family_tolerance, "m")
        as_positive("tolerance", self.tolerance, "m")
        as_count("max_iterations", self.max_iterations)
        as_positive("step_fraction", self.step_fraction, "fraction")


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

#: Observed speed and displacement beyond this many noise standard deviations count as movement.
_MOVEMENT_SIGMAS = 3.0


class OnlineGoalEstimator:
    """Goal estimates of one reach, revised as observations arrive (module docstring).

    Args:
        model: a ReachingModel or Planner of a point mass (activation stages allowed) whose plans are
            rotation-invariant (ValueError otherwise, e.g. for the Panda or per-channel noise).
        start: the state at the reach's start (nx,) or [q; qdot] (2n,), at rest (zero velocity and force).
        prior_goal: g_bar (d,) m; None: the start's hand position (with the weak default std, a prior that
            only keeps the estimate finite).
        prior_std: the prior's standard deviation (m): a number, d numbers, None (the weak default, 1 m)
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
        start, _, width = self.planner.check_inputs(start, np.zeros(d), width)
        if np.any(start[n:] != 0):
            raise ValueError("start must be at rest (zero velocity and activation), got "
                             f"{start[n:].tolist()} after the position: the online estimator's plans start from rest")
        self.start, self.width = start, width
        self.start_position = start[:n].copy()
        self.prior_goal = None if prior_goal is None else as_vector("prior_goal", prior_goal, d, "task-space position, m")
        self.prior_mean = self.start_position.copy() if self.prior_goal is None else self.prior_goal
        self.prior_cov = prior_covariance(prior_std, model, width)
        self._prior_precision = np.linalg.inv(self.prior_cov)
        self.family = families.family(width, self.options)
        _, A, _ = linearised_step_function(model.body, model.h)(np.zeros(model.state_size), np.zeros(n))
        A = np.asarray(A)
        self._powers = np.array([np.linalg.matrix_power(A, k) for k in range(model.H + 1)])
        self._R = observation_covariance(self.options.observation_std, n)
        H = model.H
        self._counts = np.zeros(H + 1)
        self._sums = np.zeros((H + 1, 2 * n))
        self._weights = np.zeros((H + 1, H + 1))
        self._last_time = -math.inf
        self._last_observation = np.zeros(2 * n)
        self.latest: GoalEstimate | None = None
        """The last estimate, None before the first update."""

    @property
    def observation_count(self) -> int:
        """Observations received so far."""
        return int(self._counts.sum())

    def update(self, time_s, position, velocity) -> GoalEstimate:
        """Add an observation and re-estimate the goal.

        Args:
            time_s: time since the reach's start (s), ≥ 0 and not before the previous observation's; any time,
                not only on the planning grid (after the horizon H·h it is read at the last step).
            position: observed hand position (d,), m.
            velocity: observed hand velocity (d,), m/s.

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
        position = as_vector("position", position, model.d, "hand position, m")
        velocity = as_vector("velocity", velocity, model.d, "hand velocity, m/s")
        observation = np.r_[position, velocity]
        grid = time_s / model.h
        nearest = min(model.H, int(round(grid)))
        before = min(model.H, int(math.floor(grid * (1 + 1e-9))))
        fraction = 0.0 if before == model.H else min(max(grid - before, 0.0), 1.0)
        self._counts[nearest] += 1
        self._sums[nearest] += observation
        self._weights[nearest, before] += 1.0 - fraction
        if fraction > 0:
            self._weights[nearest, before + 1] += fraction
        self._last_time, self._last_observation = time_s, observation
        self.latest = self._estimate(t_begin)
        return self.latest

    def _estimate(self, t_begin: float) -> GoalEstimate:
        steps = np.flatnonzero(self._counts)
        counts = self._counts[steps]
        observed = self._sums[steps] / counts[:, None]
        weights = self._weights[steps] / counts[:, None]
        noise = self._R[None] / counts[:, None, None]
        problem = _Problem(self, steps, observed, weights, noise)
        previous = self.latest
        try:
            if previous is None or previous.status in (Status.UNINFORMATIVE, Status.FAILED):
                goal = problem.cold_goal()
                if goal is None:
                    return self._result(self.prior_mean, self.prior_cov, Status.UNINFORMATIVE,
                                        "no observation shows movement: the estimate is the prior", 0, t_begin)
                rounds = 2
            else:
                goal, rounds = previous.goal, 1
            iterations = 0
            for _ in range(rounds):
                goal, info, status, message, used = problem.gauss_newton(goal)
                iterations += used
            covariance = np.linalg.inv(info)
            if not (np.all(np.isfinite(goal)) and np.all(np.isfinite(covariance))):
                raise np.linalg.LinAlgError("non-finite estimate")
        except np.linalg.LinAlgError as error:
            goal, covariance = (self.prior_mean, self.prior_cov) if previous is None else (previous.goal, previous.goal_covariance)
            return self._result(goal, covariance, Status.FAILED, f"the Gauss–Newton iteration failed ({error}); "
                                "the previous estimate is kept", 0, t_begin)
        return self._result(goal, 0.5 * (covariance + covariance.T), status, message, iterations, t_begin)

    def _result(self, goal, covariance, status: Status, message: str, iterations: int, t_begin: float) -> GoalEstimate:
        model, n = self.model, self.model.n
        prediction = self._prediction(goal, derivative=False)
        grid = self._last_time / model.h
        before = min(model.H, int(math.floor(grid * (1 + 1e-9))))
        fraction = 0.0 if before == model.H else min(max(grid - before, 0.0), 1.0)
        predicted = (1 - fraction) * prediction.mean[before, :2 * n] + fraction * prediction.mean[min(before + 1, model.H), :2 * n]
        plan = Plan(success=status in CONVERGED, status=status, message=message, objective=prediction.objective,
                    solve_time=time.perf_counter() - t_begin, iterations=iterations, t=model.h * np.arange(model.H + 1),
                    mean=prediction.mean, cov=prediction.cov, torque=prediction.torque, ee_mean=prediction.mean[:, :n].copy(),
                    ee_cov=prediction.cov[:, :n, :n].copy(), ee_velocity=prediction.mean[:, n:2 * n].copy(),
                    start=self.start.copy(), goal=np.array(goal, dtype=float), width=self.width, model_name=model.name)
        return GoalEstimate.of(plan, t_obs=self._last_time, observed_step=min(model.H, int(round(grid))),
                               observed_state=self._last_observation.copy(),
                               observation_residual=predicted - self._last_observation, prior_goal=self.prior_goal,
                               method="online", goal_covariance=np.array(covariance, dtype=float))

    def _prediction(self, goal, derivative: bool = True) -> ReachPrediction:
        """The plan from the start to ``goal``: from the family, or holding still for a goal at the start."""
        if np.linalg.norm(np.asarray(goal) - self.start_position) == 0.0:
            model = self.model
            H, nx = model.H, model.state_size
            return ReachPrediction(mean=np.tile(self.start, (H + 1, 1)), cov=np.zeros((H + 1, nx, nx)),
                                   torque=np.zeros((H, model.n)), objective=0.0,
                                   mean_jacobian=np.zeros((H + 1, nx, model.d)))
        return self.family.prediction(self.start_position, goal, derivative=derivative)


class _Problem:
    """One update's MAP problem: the averaged observations at ``steps`` and the Gauss–Newton iteration."""

    def __init__(self, estimator: OnlineGoalEstimator, steps, observed, weights, noise):
        self.e, self.steps, self.observed, self.weights, self.noise = estimator, steps, observed, weights, noise
        self.m = observed.shape[1]

    def _columns(self, prediction: ReachPrediction) -> np.ndarray:
        """[r, d mu / d g] at the observed steps (S, 2n, 1 + d), r the averaged residual y - mu."""
        mean = self.weights @ prediction.mean[:, :self.m]
        jacobian = np.einsum("sj,jkd->skd", self.weights, prediction.mean_jacobian[:, :self.m])
        return np.concatenate([(self.observed - mean)[:, :, None], jacobian], axis=2)

    def _terms(self, whitening: ObservationWhitening, goal):
        """(objective, G^T G + P0^-1, G^T e - P0^-1 (g - g_bar)) at ``goal`` under ``whitening``."""
        e = self.e
        whitened = whitening.apply(self._columns(e._prediction(goal)))
        d = len(goal)
        residual, G = whitened[:, :, 0].ravel(), whitened[:, :, 1:].reshape(-1, d)
        offset = goal - e.prior_mean
        objective = 0.5 * float(residual @ residual + offset @ e._prior_precision @ offset)
        return objective, G.T @ G + e._prior_precision, G.T @ residual - e._prior_precision @ offset

    def _projected(self, goal: np.ndarray) -> np.ndarray:
        """The goal moved into the family's range of distances from the start."""
        e = self.e
        offset = goal - e.start_position
        D = np.linalg.norm(offset)
        low, high = e.family.distances[0], e.family.distances[-1]
        if D == 0:
            return e.start_position + low * np.eye(len(goal))[0]
        return e.start_position + offset * (np.clip(D, low, high) / D)

    def gauss_newton(self, goal: np.ndarray):
        """Gauss–Newton from ``goal`` with the covariance of the plan to it held fixed: (goal, information
        matrix (d, d) m^-2, status, message, iterations)."""
        e = self.e
        goal = self._projected(np.asarray(goal, dtype=float))
        whitening = ObservationWhitening(e._prediction(goal, derivative=False).cov, self.steps, self.noise, e._powers, self.m)
        objective, info, gradient = self._terms(whitening, goal)
        options = e.options
        for iteration in range(1, options.max_iterations + 1):
            step = np.linalg.solve(info, gradient)
            limit = options.step_fraction * max(np.linalg.norm(goal - e.start_position), e.width)
            length = np.linalg.norm(step)
            if length > limit:
                step *= limit / length
            for _ in range(10):
                trial = self._projected(goal + step)
                trial_objective, trial_info, trial_gradient = self._terms(whitening, trial)
                if trial_objective <= objective + 1e-12 * abs(objective):
                    break
                step *= 0.5
            else:
                return goal, info, Status.SOLVED_ACCEPTABLE, "no Gauss–Newton step lowers the objective", iteration
            moved = np.linalg.norm(trial - goal)
            goal, objective, info, gradient = trial, trial_objective, trial_info, trial_gradient
            if moved <= options.tolerance:
                D = np.linalg.norm(goal - e.start_position)
                if D >= e.family.distances[-1] * (1 - 1e-9):
                    return goal, info, Status.MAX_ITERATIONS, (f"the estimate sits at the largest distance the reach "
                                                               f"family covers ({e.family.distances[-1]:g} m)"), iteration
                return goal, info, Status.SOLVED, f"converged in {iteration} Gauss–Newton iterations", iteration
        return goal, info, Status.MAX_ITERATIONS, f"no convergence in {options.max_iterations} Gauss–Newton iterations", options.max_iterations

    def cold_goal(self) -> np.ndarray | None:
        """The best member of the family along the observed directions (latest velocity, latest displacement
        from the start, and the prior's direction), scored by the observations' likelihood with each step's
        error taken independently, plus the prior; None when nothing moved and the prior sits at the start."""
        e = self.e
        n, d = e.model.n, e.model.d
        sigma_q, sigma_v = e.options.observation_std
        latest = e._last_observation
        directions = []
        if np.linalg.norm(latest[n:]) > _MOVEMENT_SIGMAS * sigma_v:
            directions.append(latest[n:] / np.linalg.norm(latest[n:]))
        displacement = latest[:n] - e.start_position
        if np.linalg.norm(displacement) > _MOVEMENT_SIGMAS * sigma_q:
            directions.append(displacement / np.linalg.norm(displacement))
        prior_offset = e.prior_mean - e.start_position
        if np.linalg.norm(prior_offset) > 0:
            directions.append(prior_offset / np.linalg.norm(prior_offset))
        if not directions:
            return None
        family = e.family
        best, best_score = None, math.inf
        for u in directions:
            goals = e.start_position + family.distances[:, None] * u
            scores = [self._independent_score(family.prediction(e.start_position, g, derivative=False), g) for g in goals]
            k = int(np.argmin(scores))
            if scores[k] < best_score:
                best, best_score = goals[k], scores[k]
        return best

    def _independent_score(self, prediction: ReachPrediction, goal) -> float:
        e = self.e
        r = self.observed - self.weights @ prediction.mean[:, :self.m]
        S = prediction.cov[self.steps][:, :self.m, :self.m] + self.noise
        solved = np.linalg.solve(S, r[:, :, None])[:, :, 0]
        _, log_det = np.linalg.slogdet(S)
        offset = goal - e.prior_mean
        return 0.5 * float(np.sum(r * solved) + log_det.sum() + offset @ e._prior_precision @ offset)
