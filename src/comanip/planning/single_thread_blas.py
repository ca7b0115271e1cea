"""One BLAS thread while a solve runs (:class:`SingleThreadBlas`).

The Newton systems of a reach have a few hundred unknowns: one BLAS thread solves them fastest, and a
multi-threaded BLAS on a busy machine waits for cores.
"""

from __future__ import annotations

from threadpoolctl import ThreadpoolController


class SingleThreadBlas:
    """A context in which the BLAS libraries loaded when it was made run on one thread (their thread counts are
    restored on leaving; nested contexts leave them to the outermost). threadpoolctl's own ``limit`` looks the
    libraries up on every entry, which costs about as much as a point mass's Newton step."""

    def __init__(self):
        self._libraries = ThreadpoolController().select(user_api="blas").lib_controllers
        self._depth, self._restore = 0, []

    def __enter__(self):
        if self._depth == 0:
            self._restore = [(library, library.num_threads) for library in self._libraries if library.num_threads != 1]
            for library, _ in self._restore:
                library.set_num_threads(1)
        self._depth += 1
        return self

    def __exit__(self, *exception):
        self._depth -= 1
        if self._depth == 0:
            for library, threads in self._restore:
                library.set_num_threads(threads)
        return False
