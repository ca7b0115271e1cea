"""The one Newton iteration every solver in comanip runs, the active-set SQP of
:mod:`comanip.optim.active_set_newton` among them.

One pass of :func:`newton_iterate`:

1. when the budget is spent (``max_iterations``) or ``expired()``: stop, as a solution if the iterate is one
   (step 3), else with status ``max_iterations`` or ``max_wall_time``;
2. ``method.begin(state)``: count the iteration (a method that counts something else, such as linearisations, does
   nothing here) and evaluate what the iterate lacks (``method.complete``); when the caller does not need the
   gradient at the point the budget ends on (``gradient_at_end=False``) and this pass spends the budget,
   ``method.last_iteration(state)`` tells the method so: it may accept its next point without the gradient there
   (a real-time iteration's last point, whose gradient only a status would read);
3. ``method.converged(state)``: a :class:`Stop` when the iterate is a solution (the test that needs no step); a
   solution then goes through ``method.settle(state, stop)``, the method's last stage at a solution (a last
   Newton step, a new active set): the final :class:`Stop`, or None when the stage moved the iterate, which is
   then tested again;
4. ``method.direction(state)``: the Newton direction at the iterate, or a :class:`Stop` found while computing it
   (a Hessian that cannot be factored);
5. ``method.solved_along(state, direction)``: a :class:`Stop` when what the direction computed shows the iterate
   is a solution (a constrained point's multipliers), settled as in step 3;
6. ``method.globalise(state, direction)``: a line search or a trust region; True when the iterate moved;
7. otherwise ``method.recover(state, direction)``: None to try again from the same iterate (a stronger
   regularisation, a fresh Hessian), or the :class:`Stop` that ends the solve.

``method.result(state, stop)`` turns the state into the :class:`~comanip.optim.SolverResult`. What differs between the
solvers (the working set of constraints, secant corrections, trust regions, a projection onto a feasible
range) lives in their methods, never in this loop. A method that subclasses :class:`NewtonMethod` inherits the
stages it does not need: ``settle`` keeps the stop, ``solved_along`` finds nothing.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Callable, Generic, Protocol, TypeVar

from comanip.optim.result import SolverResult
from comanip.optim.status import Status

S = TypeVar("S")
D = TypeVar("D")


@dataclass(frozen=True)
class Stop:
    """Why a solve ends: its status (a :class:`Status`, or a ``str`` enum of the layer whose hooks stop the solve)
    and the status in words."""

    status: StrEnum
    message: str


class NewtonMethod(Protocol[S, D]):
    """What :func:`newton_iterate` asks of a solver, for its state S (the iterate and what the method
    remembers between iterations) and its directions D."""

    def iterations(self, state: S) -> int:
        """The iterations spent so far (what ``max_iterations`` bounds)."""

    def begin(self, state: S) -> None:
        """Called once per pass, after the budget checks."""

    def last_iteration(self, state: S) -> None:
        """This pass spends the budget and the caller does not need the gradient at the point it accepts: the method
        may leave it unevaluated (``complete`` evaluates it)."""

    def complete(self, state: S) -> bool:
        """Evaluate what an iterate accepted after ``last_iteration`` lacks; True when something was (never, for a
        method that leaves nothing out)."""
        return False

    def converged(self, state: S) -> Stop | None:
        """A stop when the iterate is a solution, before any direction is computed; only tests."""

    def settle(self, state: S, stop: Stop) -> Stop | None:
        """The last stage at an iterate ``converged`` or ``solved_along`` stopped at: the final stop, or None after
        moving the iterate (to be tested again)."""
        return stop

    def direction(self, state: S) -> D | Stop:
        """The step to try from the iterate, or why the solve ends."""

    def solved_along(self, state: S, direction: D) -> Stop | None:
        """A stop when what ``direction`` computed shows the iterate is a solution; only tests."""
        return None

    def globalise(self, state: S, direction: D) -> bool:
        """Move the iterate along ``direction`` (line search or trust region); False when it did not move."""

    def recover(self, state: S, direction: D) -> Stop | None:
        """After ``direction`` failed: None to try again from the iterate, or why the solve ends."""

    def result(self, state: S, stop: Stop) -> SolverResult:
        """The solve's result at the iterate."""


def never() -> bool:
    """The ``expired`` of a solve without a wall-time budget (no clock read per iteration)."""
    return False


def newton_iterate(method: NewtonMethod[S, D], state: S, *, max_iterations: int,
                   expired: Callable[[], bool] = never, gradient_at_end: bool = True) -> SolverResult:
    """Run ``method`` from ``state`` until it stops (module docstring); never raises for an unconverged solve.
    ``gradient_at_end=False``: the pass that spends ``max_iterations`` may end on a point without its gradient (the
    result's optimality NaN, and a solution there not recognised until :meth:`NewtonSolve.completed`)."""
    while True:
        spent = method.iterations(state) >= max_iterations
        if spent or expired():
            # the iterate the budget ends on may be a solution: then it is reported as one
            stop = _solution(method, state) or (
                Stop(Status.MAX_ITERATIONS, f"no convergence in {max_iterations} Newton iterations") if spent else
                Stop(Status.MAX_WALL_TIME, "the wall-time budget ran out"))
            return method.result(state, stop)
        method.begin(state)
        if not gradient_at_end and method.iterations(state) >= max_iterations:
            method.last_iteration(state)
        stop = _solution(method, state)
        if stop is None:
            direction = method.direction(state)
            if isinstance(direction, Stop):
                stop = direction
            elif (solved := method.solved_along(state, direction)) is not None:
                stop = method.settle(state, solved)
                if stop is None:
                    continue
            elif method.globalise(state, direction):
                continue
            else:
                stop = method.recover(state, direction)
        if stop is not None:
            return method.result(state, stop)


def _solution(method: NewtonMethod[S, D], state: S) -> Stop | None:
    """The stop at the iterate when it is a solution (``converged``, then ``settle`` until it leaves the iterate
    where it is), else None."""
    while (stop := method.converged(state)) is not None:
        settled = method.settle(state, stop)
        if settled is not None:
            return settled
    return None


class NewtonSolve(Generic[S]):
    """A solve run in stages: :meth:`advance` iterates until the iterations spent reach a budget (or the method
    stops) and returns the result there; a later call with a larger budget goes on from that iterate along the same
    iterates one call with the larger budget would have taken (a pause only reads the state). ``final``: the result
    of a solve that ended before it started (e.g. a start where f is not finite)."""

    def __init__(self, method: NewtonMethod[S, D] | None, state: S | None, expired: Callable[[], bool] = never,
                 final: SolverResult | None = None):
        self.method, self.state, self.expired, self.final = method, state, expired, final
        self._last = final

    @property
    def finished(self) -> bool:
        """True once the solve has stopped for a reason other than its budget."""
        return self.final is not None

    def advance(self, max_iterations: int, gradient_at_end: bool = True) -> SolverResult:
        """The result after at most ``max_iterations`` iterations in all (the final result once finished).
        ``gradient_at_end=False``: the iteration that spends ``max_iterations`` may leave the gradient at its point
        unevaluated (:func:`newton_iterate`); :meth:`completed` evaluates it."""
        if self.final is None:
            result = newton_iterate(self.method, self.state, max_iterations=max_iterations, expired=self.expired,
                                    gradient_at_end=gradient_at_end)
            if result.status is not Status.MAX_ITERATIONS:
                self.final = result
            self._last = result
            return result
        return self.final

    def completed(self) -> SolverResult:
        """The last result with everything at its point evaluated (the gradient an ``advance(...,
        gradient_at_end=False)`` left out): its optimality known, and status 'solved' where the point is a solution.
        A solve its wall budget stopped on such a point is completed too."""
        last = self.final if self.final is not None else self._last
        if last is None:
            raise ValueError("completed() reads the result of an advance(); call advance() first")
        if self.method is None or not self.method.complete(self.state):
            return last
        stop = _solution(self.method, self.state) or Stop(last.status, last.message)
        result = self.method.result(self.state, stop)
        if self.final is not None:
            self.final = result
        self._last = result
        return result
