"""Posterior over a few candidate goals from states observed during a reach (beyond the paper).

Each candidate goal g_c gets the model's plan from the start, and with it a Gaussian belief over the arm's
state at every step (docs/formulation.md §2). Observations s_1..s_K at steps n_1 ≤ … ≤ n_K (n_k = floor(t_k / h), see
:mod:`comanip.estimation.observation`) are scored jointly under that belief:

    [s_1; …; s_K] ~ N([mu_n1; …; mu_nK], C + I_K ⊗ R),   C_jk = Phi(n_j, n_k) Sigma_nk  (n_j ≥ n_k)

with Phi(b, a) = A_{b-1} ⋯ A_a the state-transition matrix of the linearised belief dynamics along the plan
(the same A_i that propagate Sigma), so observations of one reach are correlated as the open-loop model says,
not treated as independent draws. R = diag(sigma_q² I_n, sigma_qdot² I_n) is an observation-noise floor: the
model's Sigma_0 = 0 (the start is known exactly) and Sigma grows from zero, so without R an observation at
t = 0, or any sensor noise, would meet a singular covariance. Bayes' rule over the candidates,

    P(g_c | s_1..k) ∝ P(g_c) N(s_1..k; mu_c, C_c + R),

is reported for every prefix k = 1..K: the sequence of posteriors a robot would hold as observations arrive.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.special import logsumexp

from comanip.arguments import as_matrix, as_optional_positive
from comanip.estimation.one_shot.goal_estimator import EstimatorCache, default_estimators
from comanip.estimation.observation import OBSERVATION_STD, observation_covariance, observed_sequence, prefix_log_likelihoods
from comanip.estimation.estimate_status import EstimateStatus
from comanip.optim import Status
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner

@dataclass
class GoalPosterior:
    """Posterior over candidate goals after each prefix of the observations. K observations, C candidates."""

    candidates: np.ndarray
    """Candidate goals (C, d), m."""
    times: np.ndarray
    """Observation times (K,), s."""
    steps: np.ndarray
    """Plan steps of the observations (K,), floor(t / h)."""
    probabilities: np.ndarray
    """P(g_c | observations 1..k) (K, C): row k uses the first k + 1 observations; rows sum to 1."""
    log_likelihoods: np.ndarray
    """log N(observations 1..k; belief of candidate c) (K, C)."""
    prior: np.ndarray
    """Prior probability of each candidate (C,)."""
    plans: list[Plan]
    """The plan to each candidate from the start, whose belief scores the observations."""
    width: float
    """Goal width w (m) the candidates were planned with."""
    observation_std: tuple[float, float]
    """Observation-noise floor (position std, velocity std) in state units."""
    start: np.ndarray = field(default_factory=lambda: np.zeros(0))
    """Start state s_0 (2n,)."""
    solve_time: float = 0.0
    """Wall time (s), planning included."""

    @property
    def success(self) -> bool:
        """True when every candidate's plan converged (a posterior over unconverged plans is less trustworthy)."""
        return all(plan.converged for plan in self.plans)

    @property
    def status(self) -> Status | EstimateStatus:
        """'solved' when every candidate's plan converged, else 'plans_not_converged' (:attr:`message` says which)."""
        return Status.SOLVED if self.success else EstimateStatus.PLANS_NOT_CONVERGED

    @property
    def message(self) -> str:
        failed = [i for i, plan in enumerate(self.plans) if not plan.converged]
        return "every candidate's plan converged" if not failed else f"plans of candidates {failed} did not converge"

    @property
    def entropy(self) -> np.ndarray:
        """Shannon entropy of each posterior (K,), nats: log C for a uniform one, 0 for a certain one."""
        p = self.probabilities
        return -np.sum(np.where(p > 0, p * np.log(np.where(p > 0, p, 1.0)), 0.0), axis=1)

    @property
    def most_likely(self) -> np.ndarray:
        """Index of the most probable candidate after each prefix (K,)."""
        return np.argmax(self.probabilities, axis=1)

    def to_dict(self) -> dict:
        """JSON-ready summary (plans left out; save them one by one)."""
        return {"candidates": self.candidates.tolist(), "times": self.times.tolist(), "steps": self.steps.tolist(),
                "probabilities": self.probabilities.tolist(), "log_likelihoods": self.log_likelihoods.tolist(),
                "prior": self.prior.tolist(), "entropy": self.entropy.tolist(), "most_likely": self.most_likely.tolist(),
                "width": self.width, "observation_std": list(self.observation_std), "success": self.success,
                "status": self.status, "message": self.message, "solve_time": self.solve_time}


def goal_posterior(model, start, observed_states, times, candidate_goals, width: float | None = None, *,
                   prior=None, observation_std=OBSERVATION_STD, warm_start: GoalPosterior | None = None,
                   max_wall_time: float | None = None, cache: EstimatorCache | None = None) -> GoalPosterior:
    """Probability of each candidate goal given states observed during a reach, after each observation.

    Args:
        model: a :class:`~comanip.ReachingModel`, a :class:`~comanip.Planner` or a :class:`GoalEstimator`;
            the planner a model or planner needs is built once and kept in ``cache``.
        start: start state s_0 (2n,) of the reach, m and m/s (rad, rad/s for joints).
        observed_states: observed states [q; qdot] (K, 2n), in time order; a single state may be (2n,).
        times: their times (K,) after the start, s, non-decreasing, in [0, H·h]; each is scored at the
            plan step floor(t / h) (nearest earlier step).
        candidate_goals: candidate goals (C, d), m, C ≥ 1.
        width: goal width w (m) the candidates are planned with; the model's default when None.
        prior: prior probabilities (C,) (normalised here); uniform when None.
        observation_std: observation-noise floor (position std in m or rad, velocity std in m/s or rad/s).
        warm_start: a previous posterior. With the same start, candidates and width its plans are reused
            (a new observation costs no solve); otherwise they warm-start the new plans.
        max_wall_time: planning budget (s) per candidate; a late plan is used as it stands.
        cache: where the planner is kept between calls; None: the package's default cache
            (:func:`comanip.estimation.one_shot.goal_estimator.default_estimators`).

    Returns:
        A :class:`GoalPosterior`; ``probabilities[k]`` is the posterior after observations 0..k.
    """
    estimator = (cache or default_estimators()).estimator(model)
    planner, model = estimator.planner, estimator.model
    t_begin = time.perf_counter()
    start, _, width = planner.check_inputs(start, np.zeros(model.d), width)
    states, times, steps = observed_sequence(model, observed_states, times)
    candidates = _candidates(candidate_goals, model.d)
    prior = _prior(prior, len(candidates))
    R = observation_covariance(observation_std, model.n)
    max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")

    plans = _candidate_plans(planner, start, candidates, width, warm_start, max_wall_time)
    log_likelihoods = np.column_stack([prefix_log_likelihoods(plan, states, steps, R, estimator.step_jacobians) for plan in plans])
    log_posterior = np.log(prior) + log_likelihoods
    probabilities = np.exp(log_posterior - logsumexp(log_posterior, axis=1, keepdims=True))
    return GoalPosterior(candidates=candidates, times=times, steps=steps, probabilities=probabilities,
                         log_likelihoods=log_likelihoods, prior=prior, plans=plans, width=width,
                         observation_std=tuple(float(v) for v in observation_std), start=start,
                         solve_time=time.perf_counter() - t_begin)


def _candidates(candidate_goals, d: int) -> np.ndarray:
    try:
        candidates = np.asarray(candidate_goals, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"candidate_goals must be an array of goals (C, {d}) in m, got {candidate_goals!r}") from None
    if candidates.size == 0:
        raise ValueError(f"candidate_goals must hold at least one goal (C, {d}) in m, got none")
    if candidates.ndim != 2:
        raise ValueError(f"candidate_goals must have shape (C, {d}) (one goal per row, m), got shape {candidates.shape}")
    return as_matrix("candidate_goals", candidates, (len(candidates), d), "goal positions, m")


def _prior(prior, count: int) -> np.ndarray:
    if prior is None:
        return np.full(count, 1.0 / count)
    prior = as_matrix("prior", prior, (count,), "probability per candidate")
    if np.any(prior < 0) or prior.sum() <= 0:
        raise ValueError(f"prior must be non-negative with a positive sum (one probability per candidate), got {prior.tolist()}")
    return prior / prior.sum()


def _candidate_plans(planner: Planner, start, candidates, width, warm_start, max_wall_time) -> list[Plan]:
    """One plan per candidate; reused from ``warm_start`` when it planned the very same reaches."""
    if warm_start is not None and not isinstance(warm_start, GoalPosterior):
        raise ValueError(f"warm_start must be a previous GoalPosterior, got {type(warm_start).__name__}")
    if warm_start is not None and warm_start.candidates.shape == candidates.shape:
        same = (np.array_equal(warm_start.candidates, candidates) and np.array_equal(warm_start.start, start)
                and warm_start.width == width)
        if same:
            return list(warm_start.plans)
        return [planner.solve(start, goal, width, warm_start=previous, max_wall_time=max_wall_time)
                for goal, previous in zip(candidates, warm_start.plans)]
    return [planner.solve(start, goal, width, max_wall_time=max_wall_time) for goal in candidates]

