"""The planner's reference strategy (:class:`IpoptReachSolver`): IPOPT on the whole single-shooting problem with
CasADi's exact Hessian, point masses only."""

from __future__ import annotations

import casadi as ca
import numpy as np

from comanip.optim import LocalModel, SolverResult
from comanip.planning.ipopt_status import IpoptDeadline, IpoptSolver, ipopt_status
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.single_thread_blas import SingleThreadBlas


class IpoptReachSolver(ReachSolver):
    """IPOPT with CasADi's exact Hessian of the expanded problem, built once; ``SolverOptions.tolerance`` is its
    ``tol`` and ``SolverOptions.ipopt`` its extra options."""

    def __init__(self, problem: ReachProblem, options, blas: SingleThreadBlas, max_iterations: int):
        super().__init__(problem, options, blas, max_iterations)
        params = ca.vertcat(problem.s0, problem.goal, problem.width)
        ipopt = {"print_level": 0, "sb": "yes", "max_iter": self.max_iterations, "tol": options.tolerance, **options.ipopt}
        deadline = IpoptDeadline(problem.tau.numel(), params.shape[0])
        function = ca.nlpsol("planner", "ipopt",
                             {"x": ca.vec(problem.tau), "p": params, "f": -problem.objective / problem.best_objective},
                             {"ipopt": ipopt, "print_time": False, "error_on_fail": False, "iteration_callback": deadline})
        self._ipopt = IpoptSolver(function, deadline)

    def run(self, guess: np.ndarray, params: ReachParameters, deadline: float) -> SolverResult[np.ndarray, LocalModel]:
        function, model = self._ipopt.function, self.problem.model
        self._ipopt.deadline.time = deadline
        result = function(x0=np.ravel(guess), p=params.vector)
        stats = function.stats()
        status = ipopt_status(stats, self._ipopt.deadline)
        torque = np.asarray(result["x"]).reshape(model.H, model.n)
        return SolverResult(torque, float(result["f"]), status, stats["return_status"], int(stats.get("iter_count", 0)), np.nan)

    def objective(self, torque: np.ndarray, params: ReachParameters) -> float:
        return self.problem.objective_value(torque, params.start, params.goal, params.width)

    def ends_at_goal(self, torque: np.ndarray, params: ReachParameters) -> bool:
        rollout = self.problem.trajectory(tau=np.ravel(torque), s0=params.start, goal=params.goal, width=params.width)
        return bool(np.linalg.norm(np.asarray(rollout["ee_mean"])[:, -1] - params.goal) <= params.width)
