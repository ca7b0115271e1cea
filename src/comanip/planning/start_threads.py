"""Solving a cold search's starts side by side on threads (:class:`StartThreads`).

An arm's cold solve without a reach library runs every minimum-jerk start to convergence and keeps the best
plan. The starts are independent, and a Newton iteration on an arm spends most of its time in compiled CasADi
functions and LAPACK, which run outside Python's interpreter lock, so threads solve them side by side on a
machine's cores. Each thread evaluates with its own copy of the terms (their evaluation buffers are not
shared); every start is solved exactly as it would be alone, so the plans do not depend on the number of
threads.
"""

from __future__ import annotations

import os
import threading
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
    """Threads for one planner's starts, created on first use, each with its own copy of the planner's terms.

    Args:
        curvature: the planner's terms; each thread gets ``curvature.for_another_thread()``.
        threads: the most starts solved at once.
    """

    def __init__(self, curvature: LinearisedCurvature, threads: int):
        self.curvature, self.threads = curvature, threads
        self._executor: ThreadPoolExecutor | None = None
        self._local = threading.local()

    def map(self, solve: Callable[[object, LinearisedCurvature], T], starts: Sequence) -> list[T]:
        """[solve(start, terms) for each start], the solves running side by side, in the order of ``starts``;
        ``terms`` is the calling thread's copy of the curvature. An exception in a solve is raised here."""
        if self._executor is None:
            self._executor = ThreadPoolExecutor(max_workers=self.threads, thread_name_prefix="comanip-start")
        futures = [self._executor.submit(self._on_thread, solve, start) for start in starts]
        return [future.result() for future in futures]

    def _on_thread(self, solve: Callable, start):
        terms = getattr(self._local, "curvature", None)
        if terms is None:
            terms = self._local.curvature = self.curvature.for_another_thread()
        return solve(start, terms)
