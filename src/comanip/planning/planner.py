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
from comanip.model import ReachingModel
from comanip.planning.initial_guess import guess_durations, minimum_jerk_torques
from comanip.planning.plan import Plan
from comanip.planning.reach_problem import ReachProblem

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
        problem = self.problem = ReachProblem(self.model)
        params = ca.vertcat(problem.s0, problem.goal, problem.width)
        ipopt = {"print_level": 0, "sb": "yes", "max_iter": self.options.max_iterations,
                 "tol": self.options.tolerance, **self.options.ipopt}
        self._deadline = _Deadline(problem.tau.numel(), params.shape[0])
        self._solver = ca.nlpsol("planner", "ipopt",
                                 {"x": ca.vec(problem.tau), "p": params, "f": -problem.objective / problem.best_objective},
                                 {"ipopt": ipopt, "print_time": False, "error_on_fail": False,
                                  "iteration_callback": self._deadline})

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
        return self._solve_from(guesses, start, goal, width, max_wall_time)

    def _initial_guesses(self, start, goal, warm_start) -> list[np.ndarray]:
        model = self.model
        if warm_start is not None:
            torque = warm_start.torque if isinstance(warm_start, Plan) else warm_start
            return [as_matrix("warm_start", torque, (model.H, model.n), "torques, N·m or N")]
        goal_q = model.body.inverse_kinematics(goal, start[: model.n])
        return [minimum_jerk_torques(model.body, model.h, model.H, start, goal_q, T)
                for T in guess_durations(model.duration, self.options.n_starts)]

    def _solve_from(self, guesses, start, goal, width, max_wall_time) -> Plan:
        t_begin = time.perf_counter()
        params = np.concatenate([start, goal, [width]])
        best = None
        iterations = 0
        for guess in guesses:
            remaining = None if max_wall_time is None else max_wall_time - (time.perf_counter() - t_begin)
            if remaining is not None and remaining <= 0 and best is not None:
                break
            torque, status, success, message, nit = self._run_solver(guess, params, remaining)
            iterations += nit
            objective = self.problem.objective_value(torque, start, goal, width)
            if not np.all(np.isfinite(torque)) or not np.isfinite(objective):
                torque, status, success = guess, "failed", False
                objective = self.problem.objective_value(guess, start, goal, width)
                message = "solver returned a non-finite plan; returning the initial guess"
            candidate = (not success, objective, torque, status, success, message)
            if best is None or candidate[:2] < best[:2]:
                best = candidate
        _, _, torque, status, success, message = best
        return self.problem.make_plan(torque, start, goal, width, status=status, success=success, message=message,
                                      solve_time=time.perf_counter() - t_begin, iterations=iterations)

    def _run_solver(self, guess: np.ndarray, params: np.ndarray, budget: float | None):
        """One IPOPT run from torques guess (H, n); returns (torques (H, n), status, success, message, iterations)."""
        self._deadline.time = np.inf if budget is None else time.perf_counter() + budget
        result = self._solver(x0=np.ravel(guess), p=params)
        stats = self._solver.stats()
        status, success = _IPOPT_STATUS.get(stats["return_status"], ("failed", False))
        if stats["return_status"] == "User_Requested_Stop" and self._deadline.expired:
            status = "max_wall_time"
        torque = np.asarray(result["x"]).reshape(self.model.H, self.model.n)
        return torque, status, success, stats["return_status"], int(stats.get("iter_count", 0))


class _Deadline(ca.Callback):
    """IPOPT iteration callback that asks the solver to stop once ``time`` (perf_counter, s) has passed."""

    def __init__(self, n_x: int, n_p: int, n_g: int = 0):
        ca.Callback.__init__(self)
        self.time = np.inf
        self._sizes = {"x": n_x, "f": 1, "g": n_g, "lam_x": n_x, "lam_g": n_g, "lam_p": n_p}
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
