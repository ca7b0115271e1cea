"""What IPOPT says, in comanip's terms: its return status mapped to a solver status, a wall-time deadline, and a
solver built with that deadline (:class:`IpoptSolver`).

Shared by every problem comanip hands to IPOPT (the planner's reference solver, the paper's eq. 11 goal
estimate).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from comanip.optim import Status

#: IPOPT return_status -> comanip status; a status not listed maps to 'failed'.
IPOPT_STATUS = {
    "Solve_Succeeded": Status.SOLVED,
    "Solved_To_Acceptable_Level": Status.SOLVED_ACCEPTABLE,
    "Maximum_Iterations_Exceeded": Status.MAX_ITERATIONS,
    "Maximum_WallTime_Exceeded": Status.MAX_WALL_TIME,
    "Maximum_CpuTime_Exceeded": Status.MAX_WALL_TIME,
}


def ipopt_status(stats: dict, deadline: "IpoptDeadline") -> Status:
    """The status of a finished IPOPT solve from its ``stats()``; a stop the deadline asked for is 'max_wall_time'."""
    if stats["return_status"] == "User_Requested_Stop" and deadline.expired:
        return Status.MAX_WALL_TIME
    return IPOPT_STATUS.get(stats["return_status"], Status.FAILED)


class IpoptDeadline(ca.Callback):
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


@dataclass(frozen=True)
class IpoptSolver:
    """An IPOPT solver built once, and the deadline its iteration callback watches (set before each solve)."""

    function: ca.Function
    deadline: IpoptDeadline
