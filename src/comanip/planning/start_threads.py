"""Solving a cold search's starts side by side on threads (:class:`StartThreads`).

An arm's cold solve without a reach library runs every minimum-jerk start and keeps the best plan. The starts are
independent, and a Newton iteration on an arm spends most of its time in compiled CasADi functions and LAPACK, which
run outside Python's interpreter lock, so threads solve them side by side on a machine's cores. Each start evaluates
with its own copy of the terms (their evaluation buffers are not shared); every start is solved exactly as it would
be alone, so the plans do not depend on the number of threads.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import Callable, Sequence, TypeVar

from comanip.planning.linearised_curvature import LinearisedCurvature

T = TypeVar("T")


def usable_cores() -> int:
    """The processors this process may run on (its affinity mask where the system has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # no affinity masks (macOS, Windows)
        return os.cpu_count() or 1


class StartThreads:
    """Threads for one planner's starts, created on first use, and a copy of the planner's terms for each start (a
    start's solve may go on, after a pause, on another thread than it began on).

    Args:
        curvature: the planner's terms; each start gets ``curvature.for_another_thread()``.
        threads: the most starts solved at once.
    """

    def __init__(self, curvature: LinearisedCurvature, threads: int):
        self.curvature, self.threads = curvature, threads
        self._executor: ThreadPoolExecutor | None = None
        self._copies: list[LinearisedCurvature] = []

    def terms(self, starts: int) -> list[LinearisedCurvature]:
        """A copy of the terms for each of ``starts`` starts (made on first need, then kept)."""
        while len(self._copies) < starts:
            self._copies.append(self.curvature.for_another_thread())
        return self._copies[:starts]

    def map(self, function: Callable[[object], T], items: Sequence) -> list[T]:
        """[function(item) for each item], the calls running side by side, in the order of ``items``. An exception
        in a call is raised here."""
        if self._executor is None:
            self._executor = ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="comanip-start")
        futures = [self._executor.submit(function, item) for item in items]
        return [future.result() for future in futures]
