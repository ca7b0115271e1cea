"""Goal estimation as inverse planning: the goal whose plan the observed state departs from least.

Notation as in :mod:`comanip.planning.reach_problem` and ``docs/notation.md``: torques tau (H·n,) stacked
step by step, start s_0, goal g (d,) m, width w (m), W = W(w) (d, d), the docs/formulation.md §4 objective J(tau, g), and
the mean state mu_no(tau) at the observed step n_o. Objectives are divided by the planner's normaliser |J_best(w)| (the best
attainable J), so the numbers the solver sees lie in about [-1, 0] for every width.

**Why not eq. 11 as printed.** The paper (Section V-C, docs/formulation.md §7) estimates the goal by

    min_{tau, g}  J(tau, g) + (g - g_bar)^T W^-1 (g - g_bar)   s.t.  mu_0 = s_0,  mu_no(tau) = s_o.

Minimising J over g as well favours goals that are cheap to reach from the observation, not the goal the
person is heading to: the reward earned near the start and the shorter remaining reach make a nearby goal
score better: eq. 11 solved from the true goal of an observed plan moves the estimate towards the start.
The plan to the true goal is not even a stationary point: dJ/dg ≠ 0 there.

**Regret.** Subtract what reaching g costs without the observation, V*(g) = min_tau J(tau, g) (the plan):

    min_g  R(g) = Jc(g) - V*(g) + (g - g_bar)^T P0^-1 (g - g_bar),    Jc(g) = min_{tau: mu_no(tau) = s_o} J(tau, g).

Jc ≥ V*, with equality exactly when the plan to g passes through s_o: the regret is the extra cost the
observation forces on a person heading to g, zero at the goal a plan was made for, so an exact observation
of a plan gives back its goal. It keeps eq. 11's objective and constraint and only removes the term V*(g)
that biases it; the regulariser is the paper's with the prior's own covariance P0 in place of W
(:mod:`comanip.estimation.goal_prior`; ``prior_std="width"`` gives the paper's P0 = W).

**First-order conditions.** By the envelope theorem dJc/dg = dJ/dg at tau_c and dV*/dg = dJ/dg at tau_s, so
the optimum is a root of

    F1 = grad_tau J(tau_c, g) + A^T lam        (H·n)   tau_c optimal subject to the observation
    F2 = mu_no(tau_c) - s_o                    (2n)    ... which it passes through
    F3 = grad_tau J(tau_s, g)                  (H·n)   tau_s the plan to g
    F4 = grad_g J(tau_c, g) - grad_g J(tau_s, g) + 2 P (g - g_bar)   (d)

with A = dmu_no/dtau and P = P0^-1 / |J_best| (zero without a prior; P0 the prior's covariance, the paper's W
with ``prior_std="width"``). For an arm both plans also keep the
joint position and velocity limits the planner keeps (the wrist's velocity limits bind in most Panda
reaches): the binding ones are held as equalities with their own multipliers, so that the plan tau_s is
the planner's plan, and the active sets are updated once F is solved (a violated limit joins, one with a
negative multiplier leaves) until they settle (:mod:`comanip.estimation.one_shot.regret_system` writes F out). Only second derivatives of J appear,
the Hessians a plan's solver uses anyway: Newton's method on F costs two of them per iteration. No NLP
solver takes a value function as an objective, so the iteration is written out here; the planner
provides its starting point. Block elimination reduces each Newton step to a d×d system in the
goal whose matrix is the regret's Hessian d²R/dg²; where that is not positive definite (far from the
optimum) its eigenvalues are mirrored so the step still descends. A trust region on the goal step, judged
by the regret the inner problems' quadratic models predict, keeps the iteration from overshooting where
the regret is flat (:func:`minimize_regret`). The returned point is checked to be a strict local minimum.

**Arms.** The Panda's Hessian of J is an approximation (:mod:`comanip.planning.linearised_curvature`), so
F's Jacobian is too, and the iteration converges linearly. Indefinite plan Hessians are shifted by a
multiple of I before the KKT solves (as the planner does), the inner steps at a fixed goal take the
first of 1, 1/2, ... that lowers the plans' l1 merits, and the iteration stops ('solved_acceptable') when
both plans are stationary to 1e-3 with their constraints met to 1e-4 and either the Newton goal step is
below 1e-2 goal widths or no goal step that long lowers the regret any more (the goal has settled as far
as the approximation can tell; from then on only the plans move). The second-order check is then made on
the regret's d×d Hessian only. Secant (SR1) corrections of the two Hessians, which the planner uses, were
tried and made things worse (none of 4 warm estimates converged in 30 iterations with them, 3 of 4 did in
2–3 without): the regret's curvature in g is a small difference of the two plans' curvatures, and
corrections learned from steps of both plans and the goal at once unsettle it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from comanip.estimation.goal_prior import GoalPrior
from comanip.estimation.one_shot.regret_system import Linearisation, RegretPoint, RegretSystem
from comanip.optim import CONVERGED, SolverResult, Status, backtrack
from comanip.optim.newton_loop import NewtonMethod, Stop, newton_iterate
from comanip.planning.path_limits import LIMIT_TOLERANCE


def minimize_regret(system: RegretSystem, point: RegretPoint, start, observed, n_o: int, observed_rows: np.ndarray, prior,
                 width: float, *, observed_position: np.ndarray, tolerance: float, max_iterations: int, step_fraction: float,
                 expired) -> SolverResult[RegretPoint, None]:
    """Newton's method on F from ``point`` until max |F| ≤ tolerance, then the second-order check.

    Globalised by a trust region on the goal step, judged by the regret itself: a trial point is kept when
    its predicted regret (:attr:`Linearisation.predicted_regret`) is lower, or, once the regret's changes
    are down at rounding level, when it halves the residual max |F| (Newton's quadratic endgame). Otherwise
    the goal step is shortened, the inner problems take a Newton step at the current goal (so the next
    comparison is made with them solved more accurately), and the step is retried. Far from the answer the
    regret is not convex, and early in a slow reach it is flat along the reach, where full steps overshoot.
    The radius starts at, and never exceeds, step_fraction·max(|g - x_o|, w), x_o = ``observed_position``
    (the observed end effector, m). ``observed_rows`` are the entries of the state s_o (2n,) the
    constrained plan must meet. ``expired()`` is asked before every step (wall-time budget).
    ``max_iterations`` bounds the number of linearisations (two Hessians of J each), which the result
    reports as ``nit``. Never raises: when the iteration does not converge, the last accepted iterate
    is returned with a status ('solved', 'solved_acceptable' (approximate Jacobian, see the module
    docstring), 'max_iterations', 'max_wall_time', 'not_a_minimum' or 'failed').

    Returns:
        A :class:`~comanip.optim.SolverResult`: x the point, fun the normalised regret J(tau_c) - J(tau_s)
        (without the regulariser), optimality max |F| (normalised gradient units; m, m/s or rad, rad/s for F2).
    """
    method = RegretNewton(system, start, observed, n_o, observed_rows, prior, width, observed_position=observed_position,
                          tolerance=tolerance, max_iterations=max_iterations, step_fraction=step_fraction)
    state = method.first_state(point)
    try:
        return newton_iterate(method, state, max_iterations=max_iterations, expired=expired)
    except np.linalg.LinAlgError:
        return method.result(state, Stop(Status.FAILED, "a Newton system was singular (the observation does not pin the torques down)"))


@dataclass
class RegretState:
    """The iterate, its linearisation, and the trust region's radius on the goal step (m)."""

    point: RegretPoint
    linearisation: Linearisation
    radius: float
    active_set_rounds: int = 0
    """Updates of the plans' active sets after convergence."""


@dataclass
class RegretNewton(NewtonMethod[RegretState, RegretPoint | None]):
    """One estimate's fixed data (start, observation, prior, width), the linearisations made so far, and the
    hooks of :func:`~comanip.optim.newton_loop.newton_iterate` (:func:`minimize_regret`)."""

    system: RegretSystem
    start: np.ndarray
    observed: np.ndarray
    n_o: int
    observed_rows: np.ndarray
    prior: GoalPrior | None
    width: float
    observed_position: np.ndarray
    tolerance: float
    max_iterations: int
    step_fraction: float
    count: int = 0
    """Linearisations at moved points (the iterations reported)."""

    def __post_init__(self):
        path_limits = self.system.path_limits
        self.excluded_c = self.system.limits_at_step(self.n_o) if path_limits.active else np.zeros(0, dtype=int)

    def first_state(self, point: RegretPoint) -> RegretState:
        """The state at ``point``, with the limits binding there (within 1e-4) held from the first step on."""
        linearisation = self.linearise(point)
        updated = _updated_active_sets(point, linearisation, self.excluded_c, threshold=-_INITIAL_MARGIN)
        if updated is not None:
            point, linearisation = updated, self.linearise(updated)
        return RegretState(point, linearisation, self.ceiling_at(point))

    def ceiling_at(self, at: RegretPoint) -> float:
        return self.step_fraction * max(np.linalg.norm(at.goal - self.observed_position), self.width)

    def iterations(self, state: RegretState) -> int:
        return self.count

    def begin(self, state: RegretState) -> None:
        """Iterations are linearisations, counted where they are made."""

    def converged(self, state: RegretState) -> Stop | None:
        """Converged: max |F| ≤ tolerance, or the approximate Jacobian's test (module docstring); failed where F is
        not finite."""
        linearisation = state.linearisation
        if not np.isfinite(linearisation.residual):
            return Stop(Status.FAILED, "J is not finite at the starting point")
        if linearisation.residual <= self.tolerance:
            return Stop(Status.SOLVED, "converged")
        if not self.system.exact and \
                _acceptable_without_exact_jacobian(linearisation, state.point, self.width, state.radius):
            return Stop(Status.SOLVED_ACCEPTABLE, "the goal step fell below 1e-2 goal widths, or no longer one lowers "
                                                  "the regret (approximate Jacobian)")
        return None

    def settle(self, state: RegretState, stop: Stop) -> Stop | None:
        """The active-set round at a converged point: the plans' active sets updated to the limits binding there
        and the point linearised anew (None: to be tested again), at most ``_ACTIVE_SET_ROUNDS`` times; once they
        stay, the point checked to be a strict minimum."""
        if stop.status not in CONVERGED:
            return stop
        updated = _updated_active_sets(state.point, state.linearisation, self.excluded_c, threshold=LIMIT_TOLERANCE)
        if updated is None or state.active_set_rounds >= _ACTIVE_SET_ROUNDS or self.count >= self.max_iterations:
            return _minimum_checked(stop, state.linearisation, self.system.exact)
        state.active_set_rounds += 1
        state.point, state.linearisation = updated, self.linearise(updated)
        state.radius = self.ceiling_at(updated)
        return None

    def direction(self, state: RegretState) -> RegretPoint | None:
        """The trust-region step on the goal, or None when the goal has settled: with an approximate Jacobian,
        once no goal step longer than the acceptable one lowers the regret, only the plans move on."""
        if not self.system.exact and state.radius <= _ACCEPTABLE_GOAL_STEP * self.width:
            return None
        return state.linearisation.step(min(state.radius, self.ceiling_at(state.point)), state.point)

    def globalise(self, state: RegretState, step: RegretPoint | None) -> bool:
        """Take the goal step when the trial is acceptable (the radius doubles if the step was that long); else
        shrink the radius to a quarter of the step tried."""
        if step is None:
            return False
        trial = state.point.plus(step)
        trial_linearisation = self.linearise_moved(trial)
        length, ceiling = np.linalg.norm(step.goal), min(state.radius, self.ceiling_at(state.point))
        if not _acceptable(state.linearisation, trial_linearisation):
            state.radius = 0.25 * length
            return False
        if length >= 0.99 * ceiling:
            state.radius = min(2 * state.radius, self.ceiling_at(state.point))
        state.point, state.linearisation = trial, trial_linearisation
        return True

    def recover(self, state: RegretState, step: RegretPoint | None) -> Stop | None:
        """After a rejected (or no) goal step: the inner problems' Newton step at the current goal, unless the
        trust region has collapsed (stalled)."""
        if step is not None and state.radius < _SHORTEST_GOAL_STEP * max(self.width, 1e-3):
            return Stop(Status.FAILED, "the Newton iteration stalled (no goal step lowers the regret)")
        inner_step = state.linearisation.step(0.0, state.point)
        scale = 1.0 if self.system.exact else self.inner_step_length(state.point, inner_step, state.linearisation)
        inner = state.point.plus(inner_step, scale)
        inner_linearisation = self.linearise_moved(inner)
        if np.isfinite(inner_linearisation.residual):
            state.point, state.linearisation = inner, inner_linearisation
        return None

    def result(self, state: RegretState, stop: Stop) -> SolverResult[RegretPoint, None]:
        linearisation = state.linearisation
        return SolverResult(state.point, linearisation.J_c - linearisation.J_s, stop.status, stop.message, self.count,
                            linearisation.residual)

    def linearise(self, at: RegretPoint) -> Linearisation:
        return self.system.linearise(at, self.start, self.observed, self.n_o, self.observed_rows, self.prior, self.width)

    def linearise_moved(self, at: RegretPoint) -> Linearisation:
        """The linearisation at a point the iteration moved to, counted as an iteration."""
        self.count += 1
        return self.linearise(at)

    def inner_step_length(self, point: RegretPoint, step: RegretPoint, linearisation: Linearisation) -> float:
        """Step length alpha in (0, 1] for the plans' Newton step at a fixed goal (approximate Jacobian): the
        first of 1, 1/2, ... that lowers the plans' l1 merits by 1e-4 of the predicted decrease (Armijo), as
        the planner's SQP does; 1/64 if none does (or if the step does not descend)."""
        after = point.plus(step)
        weights = (2 * np.abs(np.r_[after.lam, after.nu_c]).max(initial=0.0), 2 * np.abs(after.nu_s).max(initial=0.0))
        n_c = len(point.lam) + len(point.nu_c)
        # along a step that meets the linearised constraints, d|c|_1/dalpha = -|c|_1
        slope = (linearisation.grad_c @ step.tau_c - weights[0] * np.abs(linearisation.F2[:n_c]).sum()
                 + linearisation.grad_s @ step.tau_s - weights[1] * np.abs(linearisation.F5).sum())
        fixed = (self.start, self.observed, self.n_o, self.observed_rows, self.width, weights)
        merit = self.system.merits(point, *fixed)

        def attempt(alpha: float, bound: float) -> bool | None:
            trial = self.system.merits(point.plus(step, alpha), *fixed)
            return True if np.isfinite(trial) and trial <= bound else None

        return backtrack(attempt, merit, min(slope, 0.0), max_trials=_INNER_STEPS).alpha


def _minimum_checked(stop: Stop, linearisation: Linearisation, exact: bool) -> Stop:
    """``stop`` at a point that meets the convergence test, or 'not_a_minimum' where the second-order check fails."""
    why = linearisation.not_a_minimum(exact)
    return stop if why is None else Stop(Status.NOT_A_MINIMUM, why)


def _acceptable(current: Linearisation, trial: Linearisation) -> bool:
    if not np.isfinite(trial.residual):
        return False
    before, after = current.predicted_regret, trial.predicted_regret
    if not np.isfinite(after):
        return False
    return after < before or (trial.residual < 0.5 * current.residual and after < before + _ROUNDING * (1 + abs(before)))


def _acceptable_without_exact_jacobian(linearisation: Linearisation, point: RegretPoint, width: float, radius: float) -> bool:
    """Stop criterion for an approximate Jacobian (module docstring): both plans stationary and their
    constraints met to acceptable levels, and either the Newton goal step is short or the trust region has
    shrunk below that length (no longer goal step lowers the regret as far as the approximation can tell)."""
    if linearisation.stationarity > _ACCEPTABLE_GRADIENT or linearisation.constraint_error > _ACCEPTABLE_CONSTRAINT_ERROR:
        return False
    short = _ACCEPTABLE_GOAL_STEP * width
    return radius <= short or np.linalg.norm(linearisation.step(np.inf, point).goal) <= short


def _updated_active_sets(point: RegretPoint, linearisation: Linearisation, excluded_c: np.ndarray,
                         threshold: float) -> RegretPoint | None:
    """``point`` with the path limits c > threshold added to the plans' active sets and those with a
    negative multiplier dropped (the constrained plan never holds ``excluded_c``, the limits on the observed
    state itself); None when nothing changes."""
    active_c, nu_c = _updated_active_set(point.active_c, point.nu_c, linearisation.limits_c, threshold, excluded_c)
    active_s, nu_s = _updated_active_set(point.active_s, point.nu_s, linearisation.limits_s, threshold, np.zeros(0, dtype=int))
    if np.array_equal(active_c, point.active_c) and np.array_equal(active_s, point.active_s):
        return None
    return replace(point, active_c=active_c, nu_c=nu_c, active_s=active_s, nu_s=nu_s)


def _updated_active_set(active, nu, limits, threshold, excluded) -> tuple[np.ndarray, np.ndarray]:
    keep = nu >= -_MULTIPLIER_TOLERANCE
    added = np.setdiff1d(np.flatnonzero(limits > threshold), np.r_[active[keep], excluded])
    return np.r_[active[keep], added].astype(int), np.r_[nu[keep], np.zeros(len(added))]


_SHORTEST_GOAL_STEP = 1e-7
"""A goal step shorter than this fraction of the goal width means the iteration has stalled."""
_ROUNDING = 1e-10
"""Relative change of the (normalised) regret below which it no longer tells steps apart."""
_INNER_STEPS = 6
"""Inner steps (approximate Jacobian) tried: 1, 1/2, ..., 1/32, then 1/64 taken untried."""
_ACCEPTABLE_GRADIENT, _ACCEPTABLE_CONSTRAINT_ERROR, _ACCEPTABLE_GOAL_STEP = 1e-3, 1e-4, 1e-2
"""'solved_acceptable' (approximate Jacobian): plan stationarity, constraint error (state units), goal step (goal
widths)."""
_INITIAL_MARGIN = 1e-4
"""Limits within this distance of binding at the start (rad, rad/s) are held from the first step."""
_MULTIPLIER_TOLERANCE, _ACTIVE_SET_ROUNDS = 1e-9, 5
"""A multiplier below -this leaves the active set; at most this many active-set updates per solve."""
