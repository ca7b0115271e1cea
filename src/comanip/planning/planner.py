"""The reaching planner: the belief-space optimal control problem, built once and solved many times.

    minimise over tau_{0:H-1}   J = Σ_{i=0..H} -w_i R(mu_i, Sigma_i; g, W(w)) + nu Σ ||tau_i||²
    subject to                  mu_0 = s_0, Sigma_0 = 0, and the belief dynamics of SPEC §2.

Single shooting: the torques are the only decision variables and mu, Sigma are CasADi expressions of
them, so Sigma stays positive semi-definite at every iterate (multiple shooting over Sigma lets iterates go
indefinite, SPEC §9). Start state, goal and width are NLP parameters, so one build serves every solve.
The point-mass problems are unconstrained and solved by IPOPT with the exact Hessian.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from comanip.arguments import as_matrix, as_optional_positive, as_positive, as_vector
from comanip.belief.propagation import belief_step_function, end_effector_belief_function
from comanip.model import ReachingModel
from comanip.objectives.discounting import discount_weights
from comanip.objectives.reach_objective import reach_objective
from comanip.objectives.reward import goal_covariance
from comanip.planning.initial_guess import guess_durations, minimum_jerk_torques
from comanip.planning.plan import Plan

_IPOPT_STATUS = {
    "Solve_Succeeded": ("solved", True),
    "Solved_To_Acceptable_Level": ("solved_acceptable", True),
    "Maximum_Iterations_Exceeded": ("max_iterations", False),
    "Maximum_WallTime_Exceeded": ("max_wall_time", False),
    "Maximum_CpuTime_Exceeded": ("max_wall_time", False),
}


@dataclass(frozen=True)
class SolverOptions:
    """How the planner's NLP is solved."""

    max_iterations: int = 200
    """IPOPT iteration limit per start."""
    tolerance: float = 1e-8
    """IPOPT convergence tolerance on the normalised objective (J divided by the goal's peak reward times
    the sum of discount weights, so it lies in about [-1, 0])."""
    n_starts: int = 3
    """Minimum-jerk initial guesses tried on a cold solve (durations spread over the horizon); the best
    converged plan is returned. A warm-started solve uses the warm start only."""
    ipopt: dict = field(default_factory=dict)
    """Extra IPOPT options, passed through (e.g. {"hessian_approximation": "limited-memory"})."""


class Planner:
    """Plans reaches for one :class:`ReachingModel`; build once, then call :meth:`solve` many times.

    >>> planner = Planner(comanip.presets.planar())
    >>> plan = planner.solve(start=np.zeros(4), goal=[0.3, 0.0], width=0.02)
    >>> again = planner.solve(np.zeros(4), [0.3, 0.05], 0.02, warm_start=plan)
    """

    def __init__(self, model: ReachingModel, options: SolverOptions | None = None):
        if not isinstance(model, ReachingModel):
            raise ValueError(f"model must be a comanip.ReachingModel (e.g. comanip.presets.planar()), got {type(model).__name__}")
        self.model = model
        self.options = options or SolverOptions()
        self._build()

    def _build(self) -> None:
        model, body = self.model, self.model.body
        n, d, H = model.n, model.d, model.H
        tau = ca.SX.sym("tau", n, H)
        s0 = ca.SX.sym("s0", 2 * n)
        goal = ca.SX.sym("goal", d)
        width = ca.SX.sym("width")

        step = belief_step_function(body, model.h, model.kappa, model.noise)
        ee = end_effector_belief_function(body)
        means, covs = [s0], [ca.SX.zeros(2 * n, 2 * n)]
        for i in range(H):
            mu, Sigma = step(means[-1], covs[-1], tau[:, i])
            means.append(mu)
            covs.append(Sigma)
        ee_beliefs = [ee(m, S) for m, S in zip(means, covs)]
        weights = discount_weights(model.gamma, H, model.discount)
        W = goal_covariance(width, d, model.goal_covariance)
        J = reach_objective([x for x, _ in ee_beliefs], [S for _, S in ee_beliefs],
                            [tau[:, i] for i in range(H)], goal, W, weights, model.nu)
        # Normalise by the best reward attainable (hand on the goal with no noise at every step), so the
        # solver's tolerances mean the same thing for every width; the minimiser is unchanged.
        peak = float(np.sum(weights)) / ca.sqrt(ca.det(2 * ca.pi * W))
        params = ca.vertcat(s0, goal, width)
        self._n_params = params.shape[0]

        ipopt = {"print_level": 0, "sb": "yes", "max_iter": self.options.max_iterations,
                 "tol": self.options.tolerance, **self.options.ipopt}
        self._deadline = _Deadline(H * n, params.shape[0])
        self._solver = ca.nlpsol("planner", "ipopt", {"x": ca.vec(tau), "p": params, "f": J / peak},
                                 {"ipopt": ipopt, "print_time": False, "error_on_fail": False,
                                  "iteration_callback": self._deadline})
        self._trajectory = ca.Function(
            "trajectory", [ca.vec(tau), params],
            [ca.horzcat(*means), ca.horzcat(*covs), ca.horzcat(*[x for x, _ in ee_beliefs]),
             ca.horzcat(*[S for _, S in ee_beliefs]), J],
            ["tau", "p"], ["mean", "cov", "ee_mean", "ee_cov", "J"])
        q, qdot = ca.SX.sym("q", n), ca.SX.sym("qdot", n)
        self._ee_velocity = ca.Function("ee_velocity", [q, qdot], [ca.mtimes(body.jacobian(q), qdot)]).map(H + 1)

    def check_inputs(self, start, goal, width) -> tuple[np.ndarray, np.ndarray, float]:
        """Validated (start (2n,), goal (d,), width) or ValueError naming the argument."""
        model = self.model
        start = as_vector("start", start, 2 * model.n, "state [q; qdot] in m and m/s, or rad and rad/s")
        goal = as_vector("goal", goal, model.d, "task-space position, m")
        width = model.width if width is None else as_positive("width", width, "m")
        return start, goal, width

    def solve(self, start, goal, width: float | None = None, warm_start=None, max_wall_time: float | None = None) -> Plan:
        """Plan a reach.

        Args:
            start: start state s_0 = [q; qdot] (2n,), m and m/s (rad, rad/s for joints).
            goal: goal position (d,), m, in task space.
            width: goal width w (m) > 0; the model's default when None.
            warm_start: a previous :class:`Plan` or torques (H, n) to start from; cold multi-start when None.
            max_wall_time: wall-time budget (s) for the whole solve; the best plan so far is returned with
                status 'max_wall_time' when it runs out.

        Returns:
            A :class:`Plan`; never raises on a failed solve (check ``plan.success``).
        """
        start, goal, width = self.check_inputs(start, goal, width)
        max_wall_time = as_optional_positive("max_wall_time", max_wall_time, "s")
        guesses = self._initial_guesses(start, goal, warm_start)
        params = np.concatenate([start, goal, [width]])
        return self._solve_from(guesses, params, start, goal, width, max_wall_time)

    def _initial_guesses(self, start, goal, warm_start) -> list[np.ndarray]:
        model = self.model
        if warm_start is not None:
            torque = warm_start.torque if isinstance(warm_start, Plan) else warm_start
            return [as_matrix("warm_start", torque, (model.H, model.n), "torques, N·m or N")]
        goal_q = model.body.inverse_kinematics(goal, start[: model.n])
        return [minimum_jerk_torques(model.body, model.h, model.H, start, goal_q, T)
                for T in guess_durations(model.duration, self.options.n_starts)]

    def _solve_from(self, guesses, params, start, goal, width, max_wall_time) -> Plan:
        t_begin = time.perf_counter()
        best = None
        iterations = 0
        for guess in guesses:
            remaining = None if max_wall_time is None else max_wall_time - (time.perf_counter() - t_begin)
            if remaining is not None and remaining <= 0 and best is not None:
                break
            x, status, success, message, nit = self._run_solver(guess, params, remaining)
            iterations += nit
            objective = float(self._trajectory(x, params)[4])
            if not np.isfinite(objective):
                x, objective, status, success = ca.vec(guess.T), float(self._trajectory(ca.vec(guess.T), params)[4]), "failed", False
                message = "solver returned a non-finite plan; returning the initial guess"
            candidate = (not success, objective, x, status, success, message)
            if best is None or candidate[:2] < best[:2]:
                best = candidate
        _, objective, x, status, success, message = best
        return self._make_plan(np.asarray(x).ravel(), params, start, goal, width, status, success, message,
                               time.perf_counter() - t_begin, iterations)

    def _run_solver(self, guess: np.ndarray, params: np.ndarray, budget: float | None):
        self._deadline.time = np.inf if budget is None else time.perf_counter() + budget
        result = self._solver(x0=ca.vec(ca.DM(guess).T), p=params)
        stats = self._solver.stats()
        status, success = _IPOPT_STATUS.get(stats["return_status"], ("failed", False))
        if stats["return_status"] == "User_Requested_Stop" and self._deadline.expired:
            status = "max_wall_time"
        return result["x"], status, success, stats["return_status"], int(stats.get("iter_count", 0))

    def _make_plan(self, x, params, start, goal, width, status, success, message, solve_time, iterations) -> Plan:
        model = self.model
        mean, cov, ee_mean, ee_cov, J = (np.asarray(v) for v in self._trajectory(x, params))
        n2, d, H = 2 * model.n, model.d, model.H
        mean = mean.T
        ee_velocity = np.asarray(self._ee_velocity(mean[:, : model.n].T, mean[:, model.n :].T)).T
        return Plan(
            success=bool(success), status=status, message=message, objective=float(J.item()),
            solve_time=solve_time, iterations=iterations, t=model.h * np.arange(H + 1),
            mean=mean, cov=cov.reshape(n2, H + 1, n2).transpose(1, 0, 2),
            torque=x.reshape(H, model.n), ee_mean=ee_mean.T, ee_cov=ee_cov.reshape(d, H + 1, d).transpose(1, 0, 2),
            ee_velocity=ee_velocity, start=start, goal=goal, width=width, model_name=model.name)


class _Deadline(ca.Callback):
    """IPOPT iteration callback that asks the solver to stop once ``time`` (perf_counter, s) has passed."""

    def __init__(self, n_x: int, n_p: int):
        ca.Callback.__init__(self)
        self.time = np.inf
        self._sizes = {"x": n_x, "f": 1, "g": 0, "lam_x": n_x, "lam_g": 0, "lam_p": n_p}
        self.construct("deadline", {})

    @property
    def expired(self) -> bool:
        return time.perf_counter() > self.time

    def get_n_in(self):
        return ca.nlpsol_n_out()

    def get_n_out(self):
        return 1

    def get_name_in(self, i):
        return ca.nlpsol_out(i)

    def get_name_out(self, i):
        return "ret"

    def get_sparsity_in(self, i):
        return ca.Sparsity.dense(self._sizes[ca.nlpsol_out(i)], 1)

    def eval(self, arg):
        return [1 if self.expired else 0]


def plan_reach(model: ReachingModel, start, goal, width: float | None = None, **solve_options) -> Plan:
    """One-off plan: builds a :class:`Planner` for the model and solves once. Reuse a Planner in loops."""
    return Planner(model).solve(start, goal, width, **solve_options)
