"""Estimate the goal of a reach from its start and one state observed on the way (paper Section V-C, docs/formulation.md §7).

The person started at s_0 and was seen in state s_o at time t_o (step n_o = floor(t_o / h), the nearest
earlier step; :mod:`comanip.estimation.observation`). The estimate is a goal g_hat and the full predicted
trajectory: the model's reach from s_0 to g_hat through s_o, returned as a :class:`~comanip.Plan` (so it
plots and exports like any plan), with g_hat in ``estimate.goal``: a :class:`GoalEstimate`, a Plan with the
estimate's own fields (observed step, regret, multipliers, ...).

Two methods:

- ``"regret"`` (default): min over g of Jc(g) - V*(g) + (g - g_bar)^T W^-1 (g - g_bar), the paper's
  constrained objective minus the value of the unconstrained plan to the same goal, which makes an exact
  observation of a plan give back its goal (:mod:`comanip.estimation.one_shot.regret_newton` explains why eq. 11 as
  printed does not, with numbers). Solved by Newton's method on the planner's structured Hessians, from a
  plan or a previous estimate. Point masses and the Panda (whose plans keep the joint limits, held here
  too; approximate Hessian, so estimates end 'solved_acceptable' at a goal settled to 1e-2 goal widths).
- ``"paper"``: eq. 11 as printed, one IPOPT solve over (tau, g) with the observation as a constraint.
  Biased towards goals near the observation; kept to reproduce the paper and to compare. Point masses
  only (IPOPT needs CasADi's exact Hessian of the expanded problem, far too expensive for the Panda).

Observations before 2h: at step 1 only the velocity is held, at step 0 the estimate is the prior's plan
(status 'uninformative'); :mod:`comanip.estimation.observation` says why.

The regulariser (g - g_bar)^T P0^-1 (g - g_bar) is the paper's with the prior's own covariance P0 in place of
W: ``prior_std`` says how rough the guess g_bar is (m; default 10 m, a weak prior that moves an exact
observation's estimate by a fraction of a millimetre), and ``prior_std="width"`` gives the paper's P0 = W (W = w² I by
default), which dominates an early observation (:mod:`comanip.estimation.goal_prior`). Without a prior goal
(``prior_goal=None``) it is left out.

Every estimate reports ``goal_covariance`` (d, d) m², the Laplace approximation of the goal's posterior at
the estimate: the Gauss–Newton curvature S^T (Sigma_no + R)^-1 S of the observation's likelihood, S = d mu_no /
d g the sensitivity of the plan's mean at the observed step to the goal (from the regret's own KKT solves),
Sigma_no the plan's state covariance there and R the observation noise (``EstimatorOptions.observation_std``),
plus the prior's precision (the weak default's when there is no prior goal, which keeps it finite). For a
continuous stream of observations use :class:`comanip.estimation.OnlineGoalEstimator`.

>>> estimator = GoalEstimator(comanip.presets.cartesian())
>>> estimate = estimator.estimate(start=np.zeros(6), observed=s_o, t_obs=0.2)
>>> estimate.goal, estimate.success, estimate.regret
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np
from threadpoolctl import ThreadpoolController

from comanip.arguments import as_count, as_matrix, as_optional_positive, as_positive, as_vector
from comanip.belief.propagation import linearised_step_function
from comanip.caching.process_caches import PROCESS_CACHES
from comanip.estimation.one_shot.goal_estimate import GoalEstimate
from comanip.estimation.goal_prior import GoalPrior, prior_covariance
from comanip.estimation.one_shot.initial_goal import search_along_observed_direction, task_space_state
from comanip.estimation.observation import OBSERVATION_STD, observation_covariance, observation_step, observed_rows, observed_state
from comanip.estimation.one_shot.regret_newton import minimize_regret
from comanip.estimation.one_shot.regret_system import RegretPoint, RegretSystem
from comanip.estimation.model_reaches.estimation_planner import checked_model, estimation_planner
from comanip.model import ReachingModel
from comanip.estimation.estimate_status import EstimateStatus
from comanip.optim import CONVERGED, Status
from comanip.caching.model_cache import ModelCache
from comanip.planning.plan import Plan
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.ipopt_status import IpoptDeadline, IpoptSolver, ipopt_status
from comanip.planning.planner import Planner

METHODS = ("regret", "paper")


@dataclass(frozen=True)
class EstimatorOptions:
    """How the goal estimate is computed."""

    tolerance: float = 1e-8
    """Convergence: max |F| of the regret's first-order conditions (normalised objective per N·m or N, and
    state units for the observation constraint); IPOPT's tol for the 'paper' method."""
    max_iterations: int | None = None
    """Newton iterations ('regret'), or a tenth of IPOPT's ('paper'). None: ``exact_iterations`` for point
    masses, ``approximate_iterations`` for arms."""
    exact_iterations: int = 30
    """The limit for point masses when ``max_iterations`` is None (exact Jacobian, quadratic convergence)."""
    approximate_iterations: int = 100
    """The limit for arms when ``max_iterations`` is None (approximate Jacobian, linear convergence)."""
    step_fraction: float = 0.5
    """Largest goal step of one Newton iteration, as a fraction of the distance from the observed hand to
    the current goal (at least one goal width)."""
    search_distances: tuple[float, float] = (0.01, 1.5)
    """Range (m) of goal distances beyond the observed hand position searched for a cold start."""
    observation_std: tuple[float, float] = OBSERVATION_STD
    """Observation-noise floor (position std, velocity std in state units) used by the cold-start search."""

    def __post_init__(self):
        as_positive("tolerance", self.tolerance, "residual")
        as_count("max_iterations", self.max_iterations, optional=True)
        as_count("exact_iterations", self.exact_iterations)
        as_count("approximate_iterations", self.approximate_iterations)
        if not (isinstance(self.step_fraction, (int, float)) and 0 < self.step_fraction <= 10):
            raise ValueError(f"step_fraction must be in (0, 10] (fraction of the remaining reach), got {self.step_fraction!r}")
        low, high = (as_positive(f"search_distances[{k}]", v, "m") for k, v in enumerate(self.search_distances))
        if low >= high:
            raise ValueError(f"search_distances must be (D_min, D_max) with D_min < D_max (m), got {self.search_distances!r}")
        observation_covariance(self.observation_std, 1)


class GoalEstimator:
    """Goal estimates for one model: functions and solvers built once, reused for every observation.

    Given a model, it builds its own planner (terms compiled to C, :func:`estimation_planner`); given a
    planner, it uses that one. The 'paper' method's NLP depends on the observed step, so one is built per
    n_o on first use and kept.
    """

    def __init__(self, model: ReachingModel | Planner, options: EstimatorOptions | None = None):
        self.planner = estimation_planner(model)
        self.model = self.planner.model
        self.problem = self.planner.problem
        self.options = options or EstimatorOptions()
        self._regret = RegretSystem(self.planner)
        self.step_jacobians = linearised_step_function(self.model.body, self.model.h)
        """The body's linearised step ``(s, tau) -> (f, A, B)`` (:func:`comanip.belief.linearised_step_function`)."""
        self._blas = ThreadpoolController()
        self._paper_solvers: dict[int, IpoptSolver] = {}

    def estimate(self, start, observed, t_obs, prior_goal=None, width: float | None = None, *, prior_std=None,
                 method: str = "regret", warm_start: Plan | None = None, max_wall_time: float | None = None) -> GoalEstimate:
        """Estimate the goal of a reach from its start and a state observed at t_obs.

        Args:
            start: start state s_0 = [q; qdot] (2n,), m and m/s (rad, rad/s for joints).
            observed: observed state s_o (2n,), same units.
            t_obs: time of the observation after the start (s), in (0, H·h); it is matched to the step
                n_o = floor(t_obs / h) (nearest earlier step). At n_o = 1 only the observed velocity is
                held (the position there is fixed by the start); before h (n_o = 0) the observation says
                nothing about the goal and the estimate is the plan to ``prior_goal`` (status
                'uninformative', success False), which must then be given
                (:mod:`comanip.estimation.observation`).
            prior_goal: g_bar (d,), m, for the regulariser; None leaves it out.
            width: goal width w (m); the model's default when None.
            prior_std: how uncertain g_bar is (m): a number, d numbers, None (the weak default, 10 m) or
                "width" (the paper's W from the width); :mod:`comanip.estimation.goal_prior`.
            method: 'regret' (default) or 'paper' (eq. 11 as printed).
            warm_start: a previous estimate (its full state is reused) or any plan of this model (its torques
                and goal seed the solve, e.g. the plan to the prior goal); None searches for a start.
            max_wall_time: budget (s) for the whole estimate; the best estimate so far is returned with
                status 'max_wall_time' when it runs out.

        Returns:
            A :class:`GoalEstimate`: the plan through the observation to the estimated goal, with the observed
            step, ``observation_residual`` (mean at n_o minus the observed state, (nx,)) and, for the regret,
            ``regret`` (J units), ``residual`` (max |F|) and ``unconstrained_torque`` (the plan to the
            estimated goal, not held to the observation, (H, n)), and ``goal_covariance`` (d, d) m²; never raises on a failed solve (check
            ``success`` and ``status``).
        """
        t_begin = time.perf_counter()
        model = self.model
        checked = self._checked_request(start, observed, t_obs, prior_goal, width, prior_std, method, max_wall_time)
        start, observed, n_o, prior, width, rows = checked.start, checked.observed, checked.n_o, checked.prior, checked.width, checked.rows
        if n_o == 0:
            return self._uninformative(start, observed, float(t_obs), prior, width, method, warm_start, checked.max_wall_time, t_begin)
        point, plan_needed = self._warm_point(warm_start, len(rows)) if warm_start is not None else (None, False)

        deadline = math.inf if checked.max_wall_time is None else t_begin + checked.max_wall_time

        def remaining_time() -> float | None:
            return None if checked.max_wall_time is None else max(deadline - time.perf_counter(), 1e-6)

        if plan_needed:
            point.tau_s = self.planner.solve(start, point.goal, width, max_wall_time=remaining_time()).torque.ravel()

        def cold_point() -> RegretPoint:
            return self._cold_point(start, observed, n_o, len(rows), prior, width, remaining_time)

        if method == "regret":
            point, status, message, iterations, details = self._regret_solve(point, cold_point, start, observed, n_o, rows,
                                                                             prior, width, deadline)
        else:
            point, status, message, iterations = self._paper_solve(point if point is not None else cold_point(), start,
                                                                   observed, n_o, rows, prior, width, remaining_time())
            details = {}
        plan = self.problem.make_plan(point.tau_c.reshape(model.H, model.n), ReachParameters(start, point.goal, width),
                                      status=status, success=status in CONVERGED, message=message,
                                      solve_time=time.perf_counter() - t_begin, iterations=iterations)
        return self._estimate_of(plan, point, checked, float(t_obs), method, details)

    def _estimate_of(self, plan: Plan, point: RegretPoint, checked: "_Request", t_obs: float, method: str,
                     details: dict) -> GoalEstimate:
        """The :class:`GoalEstimate` of a solved ``plan`` through the observation, with the goal's covariance."""
        n_o, observed, prior = checked.n_o, checked.observed, checked.prior
        covariance = self._goal_covariance(point, plan, checked.start, observed, n_o, checked.rows, prior, checked.width)
        return GoalEstimate.of(plan, t_obs=t_obs, observed_step=n_o, observed_state=observed,
                               observation_residual=plan.mean[n_o] - observed, prior_goal=None if prior is None else prior.mean,
                               method=method, multipliers=point.lam.copy(), goal_covariance=covariance, **details)

    def _checked_request(self, start, observed, t_obs, prior_goal, width, prior_std, method, max_wall_time) -> "_Request":
        """:meth:`estimate`'s arguments checked (one-line errors before any work) and converted."""
        model = self.model
        start, _, width = self.planner.check_inputs(start, np.zeros(model.d), width)
        observed = observed_state(model, observed)
        n_o = observation_step(model, t_obs)
        prior_cov = prior_covariance(prior_std, model, width)
        prior = None if prior_goal is None else GoalPrior(as_vector("prior_goal", prior_goal, model.d, "task-space position, m"), prior_cov)
        check_method(model, method)
        max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")
        if n_o == 0 and prior is None:
            raise ValueError(f"t_obs = {float(t_obs):g} s falls on step 0 (before h = {model.h:g} s): the observed state is the "
                             "start itself and says nothing about the goal; give prior_goal (the estimate is then the plan to it)")
        return _Request(start, observed, n_o, prior, width, observed_rows(model, n_o), max_wall_time)

    def _goal_covariance(self, point: RegretPoint, plan: Plan, start, observed, n_o, rows, prior: GoalPrior | None, width) -> np.ndarray:
        """The Laplace covariance (d, d) m² of the estimate (module docstring); the prior's (or the weak default
        prior's) covariance where the curvature cannot be evaluated."""
        model = self.model
        fallback = prior.covariance if prior is not None else prior_covariance(None, model, width)
        precision = np.linalg.inv(fallback)
        try:
            with self._blas.limit(limits=1, user_api="blas"):
                linearisation = self._regret.linearise(point, start, observed, n_o, rows, prior, width)
                S = linearisation.A_c[:len(rows)] @ linearisation.plan_goal_sensitivity()
            R = observation_covariance(self.options.observation_std, model.n)
            C = (plan.cov[n_o][:2 * model.n, :2 * model.n] + R)[np.ix_(rows, rows)]
            covariance = np.linalg.inv(S.T @ np.linalg.solve(C, S) + precision)
        except np.linalg.LinAlgError:
            return fallback
        return 0.5 * (covariance + covariance.T) if np.all(np.isfinite(covariance)) else fallback

    def _regret_solve(self, point: RegretPoint | None, cold_point, start, observed, n_o, rows, prior, width, deadline):
        """Newton's method on the regret from ``point`` (from ``cold_point()`` when None, or when a warm start
        fails and time is left); (point, status, message, iterations, the :class:`GoalEstimate` fields it fills)."""
        model = self.model
        x_obs, _ = task_space_state(self.planner, observed)

        def newton(point: RegretPoint):
            # The Newton systems are a few hundred unknowns: one BLAS thread solves them fastest; more
            # threads wait for cores on a busy machine.
            with self._blas.limit(limits=1, user_api="blas"):
                return minimize_regret(self._regret, point, start, observed, n_o, rows, prior, width, observed_position=x_obs,
                                    tolerance=self.options.tolerance, max_iterations=self._max_iterations,
                                    step_fraction=self.options.step_fraction, expired=lambda: time.perf_counter() > deadline)

        result = newton(point if point is not None else cold_point())
        iterations = result.nit
        if (point is not None and result.status in (Status.FAILED, Status.MAX_ITERATIONS, Status.NOT_A_MINIMUM)
                and time.perf_counter() < deadline):
            # a warm start too far from the answer (e.g. the plan to a poor prior): search as if cold
            retry = newton(cold_point())
            iterations += retry.nit
            if retry.success or retry.optimality < result.optimality:
                result = retry
        point = result.x
        details = {"regret": self._regret.normaliser(width) * result.fun, "residual": result.optimality,
                   "unconstrained_torque": point.tau_s.reshape(model.H, model.n).copy()}
        return point, result.status, result.message, iterations, details

    def _uninformative(self, start, observed, t_obs, prior, width, method, warm_start, max_wall_time, t_begin) -> GoalEstimate:
        """The estimate from an observation at step 0: the plan to the prior goal, status 'uninformative'."""
        plan = self.planner.solve(start, prior.mean, width, warm_start=warm_start, max_wall_time=max_wall_time)
        message = (f"the observation at t_obs = {t_obs:g} s falls on step 0, the start itself, and says nothing about the goal: "
                   f"the estimate is the prior goal and the trajectory its plan (plan status '{plan.status}')")
        plan = replace(plan, success=False, status=EstimateStatus.UNINFORMATIVE, message=message, solve_time=time.perf_counter() - t_begin)
        return GoalEstimate.of(plan, t_obs=t_obs, observed_step=0, observed_state=observed,
                               observation_residual=plan.mean[0] - observed, prior_goal=prior.mean, method=method,
                               plan_status=plan.status, goal_covariance=prior.covariance.copy())

    @property
    def _max_iterations(self) -> int:
        if self.options.max_iterations is not None:
            return self.options.max_iterations
        return self.options.exact_iterations if self._regret.exact else self.options.approximate_iterations

    def _warm_point(self, warm_start: Plan, n_rows: int) -> tuple[RegretPoint, bool]:
        """The iterate a warm start gives, and whether its plan to the goal (tau_s) must still be solved."""
        model = self.model
        if not isinstance(warm_start, Plan):
            raise ValueError(f"warm_start must be a previous estimate or a Plan of this model, got {type(warm_start).__name__}")
        shape, unit = (model.H, model.n), "torques, N·m or N"
        tau_c = as_matrix("warm_start.torque", warm_start.torque, shape, unit).ravel()
        goal = as_vector("warm_start.goal", warm_start.goal, model.d, "m")
        if not isinstance(warm_start, GoalEstimate):  # a plain plan is a plan to its goal already
            return RegretPoint(tau_c.copy(), np.zeros(n_rows), tau_c.copy(), goal.copy()), False
        lam = np.zeros(n_rows)
        if np.size(warm_start.multipliers) == n_rows:  # from an estimate at a step like this one's
            lam = as_vector("warm_start.multipliers", warm_start.multipliers, n_rows, "multipliers")
        if warm_start.unconstrained_torque is not None:
            tau_s = as_matrix("warm_start.unconstrained_torque", warm_start.unconstrained_torque, shape, unit).ravel()
            return RegretPoint(tau_c.copy(), lam.copy(), tau_s.copy(), goal.copy()), False
        # An estimate by another method holds a trajectory through its observation, not a plan to its goal
        # (and it may even be a poor local optimum of J that passes through it, where the regret is zero):
        # the plan to its goal is solved afresh.
        return RegretPoint(tau_c.copy(), lam.copy(), tau_c.copy(), goal.copy()), True

    def _cold_point(self, start, observed, n_o, n_rows, prior, width, remaining_time) -> RegretPoint:
        """Start from the best goal along the observed direction; from the prior (or the hand) if nothing moved."""
        R = observation_covariance(self.options.observation_std, self.model.n)
        found = search_along_observed_direction(self.planner, start, observed, n_o, prior, width, R, self.options.search_distances,
                                                self.step_jacobians, remaining_time)
        if found is None:
            goal = prior.mean if prior is not None else task_space_state(self.planner, observed)[0]
            plan = self.planner.solve(start, goal, width, max_wall_time=remaining_time())
        else:
            goal, plan = found
        tau = plan.torque.ravel()
        return RegretPoint(tau.copy(), np.zeros(n_rows), tau.copy(), np.asarray(goal, dtype=float).copy())

    def _paper_solver(self, n_o: int, rows: np.ndarray) -> IpoptSolver:
        """IPOPT on eq. 11 as printed: x = (tau, g), p = (s_0, s_o, g_bar, w, prior weight 0 or 1, P0^-1 (d, d));
        the constraint holds the observed ``rows`` (fixed by n_o) of the state."""
        if n_o not in self._paper_solvers:
            p, model = self.problem, self.model
            observed = ca.SX.sym("observed", 2 * model.n)
            prior, use_prior = ca.SX.sym("prior", model.d), ca.SX.sym("use_prior")
            precision = ca.SX.sym("precision", model.d, model.d)
            error = p.goal - prior
            objective = (p.objective + use_prior * ca.dot(error, ca.mtimes(precision, error))) / (-p.best_objective)
            x = ca.vertcat(ca.vec(p.tau), p.goal)
            params = ca.vertcat(p.s0, observed, prior, p.width, use_prior, ca.vec(precision))
            deadline = IpoptDeadline(x.numel(), params.numel(), len(rows))
            ipopt = {"print_level": 0, "sb": "yes", "max_iter": self._max_iterations * 10, "tol": self.options.tolerance}
            solver = ca.nlpsol(f"goal_estimate_eq11_{n_o}", "ipopt",
                               {"x": x, "p": params, "f": objective, "g": (p.means[n_o] - observed)[rows.tolist()]},
                               {"ipopt": ipopt, "print_time": False, "error_on_fail": False, "iteration_callback": deadline})
            self._paper_solvers[n_o] = IpoptSolver(solver, deadline)
        return self._paper_solvers[n_o]

    def _paper_solve(self, point: RegretPoint, start, observed, n_o, rows, prior, width, budget):
        paper = self._paper_solver(n_o, rows)
        solver, deadline = paper.function, paper.deadline
        deadline.time = math.inf if budget is None else time.perf_counter() + budget
        d = self.model.d
        params = np.r_[start, observed, np.zeros(d) if prior is None else prior.mean, width, prior is not None,
                       np.zeros(d * d) if prior is None else prior.precision.ravel(order="F")]
        result = solver(x0=np.r_[point.tau_c, point.goal], p=params, lbg=0, ubg=0)
        stats = solver.stats()
        status = ipopt_status(stats, deadline)
        x = np.asarray(result["x"]).ravel()
        Hn = self.model.H * self.model.n
        if not np.all(np.isfinite(x)):
            status, x = Status.FAILED, np.r_[point.tau_c, point.goal]
        lam = np.asarray(result["lam_g"]).ravel()
        solved = RegretPoint(x[:Hn], lam if np.all(np.isfinite(lam)) else np.zeros_like(lam), point.tau_s, x[Hn:])
        return solved, status, stats["return_status"], int(stats.get("iter_count", 0))


class EstimatorCache(ModelCache[GoalEstimator]):
    """Goal estimators kept between calls of :func:`estimate_goal` and :func:`comanip.goal_posterior`.

    A :class:`~comanip.caching.model_cache.ModelCache` with one addition to its key: a Planner is its own key
    (its options are part of what it solves) and gets an estimator using it; a ReachingModel is keyed by
    its parameters (:func:`~comanip.caching.model_cache.model_key`, so two loads of a preset share an
    estimator) and gets an estimator with its own planner. At most ``size`` estimators are kept, the least
    recently used dropped first. Safe to share between threads; an estimator itself is not (give each
    thread its own cache or planner).
    """

    def __init__(self, size: int = 4):
        super().__init__(GoalEstimator, size)

    def key(self, model):
        return model if isinstance(model, Planner) else super().key(model)

    def estimator(self, model: ReachingModel | Planner | GoalEstimator) -> GoalEstimator:
        """The estimator for ``model``, built on first use."""
        if isinstance(model, GoalEstimator):
            return model
        return self.get(checked_model(model))


def default_estimators() -> EstimatorCache:
    """The estimator cache of this process (:data:`comanip.caching.process_caches.PROCESS_CACHES`), which
    :func:`estimate_goal` and :func:`comanip.goal_posterior` use when given none."""
    return PROCESS_CACHES.get("goal estimators", EstimatorCache)


def estimate_goal(model: ReachingModel | Planner | GoalEstimator, start, observed, t_obs, prior_goal=None,
                  width: float | None = None, *, cache: EstimatorCache | None = None, **options) -> GoalEstimate:
    """Estimate a reach's goal from a state observed at t_obs; see :meth:`GoalEstimator.estimate`.

    ``model`` may be a ReachingModel or a Planner (its estimator is built on first use and kept in
    ``cache``, :func:`default_estimators` when None), or a GoalEstimator. ``options`` go to
    :meth:`GoalEstimator.estimate` (method, warm_start, max_wall_time).
    """
    estimator = (cache or default_estimators()).estimator(model)
    return estimator.estimate(start, observed, t_obs, prior_goal, width, **options)


def check_method(model: ReachingModel, method: str) -> str:
    """``method`` if :meth:`GoalEstimator.estimate` can use it for ``model``; a one-line ValueError otherwise."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if method == "paper" and not model.body.is_linear:
        raise ValueError(f"method 'paper' (IPOPT with CasADi's exact Hessian of the expanded problem) is for point "
                         f"masses; the {model.body.name!r} body needs method 'regret'")
    return method


@dataclass(frozen=True)
class _Request:
    """An estimate's checked arguments: start s_0 (2n,), observed s_o (2n,), the observed step n_o, the prior
    (or None), the width w (m), the observed entries of s_o, and the wall-time budget (s, or None)."""

    start: np.ndarray
    observed: np.ndarray
    n_o: int
    prior: GoalPrior | None
    width: float
    rows: np.ndarray
    max_wall_time: float | None
