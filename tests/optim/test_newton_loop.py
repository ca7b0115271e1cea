"""The one Newton iteration (comanip.optim.newton_loop) on a scalar problem whose hooks are written out here:
Newton's method for the root of x³ - 2 (the minimum of x⁴/4 - 2x), a line search that may be told to fail."""

from dataclasses import dataclass

import numpy as np

from comanip.optim import SolverResult, Status
from comanip.optim.newton_loop import NewtonMethod, Stop, newton_iterate


@dataclass
class _State:
    x: float
    iterations: int = 0
    recoveries: int = 0


@dataclass
class _CubeRoot(NewtonMethod[_State, float]):
    tolerance: float = 1e-12
    failures: int = 0
    """Line searches that fail before one succeeds."""

    def iterations(self, state):
        return state.iterations

    def begin(self, state):
        state.iterations += 1

    def converged(self, state):
        return Stop(Status.SOLVED, "converged") if abs(state.x**3 - 2) <= self.tolerance else None

    def direction(self, state):
        return -(state.x**3 - 2) / (3 * state.x**2)

    def globalise(self, state, step):
        if self.failures:
            self.failures -= 1
            return False
        state.x += step
        return True

    def recover(self, state, step):
        state.recoveries += 1
        return None if state.recoveries <= 3 else Stop(Status.FAILED, "no step")

    def result(self, state, stop):
        return SolverResult(state.x, state.x**4 / 4 - 2 * state.x, stop.status, stop.message, state.iterations,
                            abs(state.x**3 - 2))


def test_newton_converges_quadratically_and_counts_its_iterations():
    result = newton_iterate(_CubeRoot(), _State(1.0), max_iterations=50)
    assert result.status == Status.SOLVED and abs(result.x - np.cbrt(2)) < 1e-12
    assert result.success and 4 <= result.nit <= 8


def test_a_spent_budget_stops_with_max_iterations_unless_the_iterate_is_a_solution():
    stopped = newton_iterate(_CubeRoot(), _State(1.0), max_iterations=2)
    assert stopped.status == Status.MAX_ITERATIONS and stopped.nit == 2 and not stopped.success
    needed = newton_iterate(_CubeRoot(), _State(1.0), max_iterations=50).nit
    # the last pass only finds the point converged: with the budget one short, the iterate the budget ends on is
    # that solution, and is reported as one
    exact = newton_iterate(_CubeRoot(), _State(1.0), max_iterations=needed - 1)
    assert exact.status == Status.SOLVED and exact.nit == needed - 1


def test_failed_steps_are_recovered_and_then_end_the_solve():
    recovered = newton_iterate(_CubeRoot(failures=2), _State(1.0), max_iterations=50)
    assert recovered.status == Status.SOLVED
    failed = newton_iterate(_CubeRoot(failures=10), _State(1.0), max_iterations=50)
    assert failed.status == Status.FAILED and failed.x == 1.0


def test_an_expired_budget_stops_with_max_wall_time():
    result = newton_iterate(_CubeRoot(), _State(1.0), max_iterations=50, expired=lambda: True)
    assert result.status == Status.MAX_WALL_TIME and result.nit == 0


@dataclass
class _ShiftedCubeRoot(_CubeRoot):
    """Settles a converged root of x³ - 2 by moving to x + 1 once: the loop tests the moved iterate again and goes on
    iterating from it, to the same root."""

    moved: bool = False

    def settle(self, state, stop):
        if self.moved:
            return stop
        self.moved, state.x = True, state.x + 1.0
        return None


def test_a_settling_stage_that_moves_the_iterate_is_followed_by_more_iterations():
    plain = newton_iterate(_CubeRoot(), _State(1.0), max_iterations=50)
    settled = newton_iterate(_ShiftedCubeRoot(), _State(1.0), max_iterations=50)
    assert settled.status == Status.SOLVED and abs(settled.x - np.cbrt(2)) < 1e-12
    assert settled.nit > plain.nit
