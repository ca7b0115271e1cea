"""The one owner of what this Python process keeps between calls when the caller passes no cache of its own.

Every cache a caller can own (a planner cache, a reach-family cache, ...) is passed in where it is used; where it is
not, the default is the one this owner made for the process, on first use, one per kind: :data:`PROCESS_CACHES`.
Each is bounded by its own size, and lives as long as the process (a pool or Dask worker has its own). A function
whose results are worth keeping for the process (a build that depends only on its arguments) is decorated with
:func:`memoised`, which keeps its latest results here too. This is the only module-level state of comanip's caches.
"""

from __future__ import annotations

import functools
import threading
from typing import Callable, TypeVar

T = TypeVar("T")


class ProcessCaches:
    """This process's default caches, one per kind, each made on first use (module docstring)."""

    def __init__(self):
        self._made: dict[str, object] = {}
        self._lock = threading.Lock()

    def get(self, kind: str, make: Callable[[], T]) -> T:
        """The cache of ``kind``, made by ``make()`` the first time it is asked for."""
        with self._lock:
            if kind not in self._made:
                self._made[kind] = make()
            return self._made[kind]

    def kinds(self) -> list[str]:
        """The kinds made so far."""
        with self._lock:
            return sorted(self._made)


PROCESS_CACHES = ProcessCaches()
"""The process's default caches (module docstring)."""


def memoised(maxsize: int) -> Callable[[Callable[..., T]], Callable[..., T]]:
    """A decorator keeping the latest ``maxsize`` results of a function of hashable arguments in
    :data:`PROCESS_CACHES` (its kind: the function's module and qualified name), the least recently used dropped
    first. For functions whose result depends on their arguments only. The decorated function has
    ``cache_clear()``; ``__wrapped__`` is the function itself."""
    if not (isinstance(maxsize, int) and maxsize >= 1):
        raise ValueError(f"maxsize must be an integer ≥ 1, got {maxsize!r}")

    def decorate(function: Callable[..., T]) -> Callable[..., T]:
        kind = f"{function.__module__}.{function.__qualname__}"

        def results():
            return PROCESS_CACHES.get(kind, lambda: functools.lru_cache(maxsize=maxsize)(function))

        @functools.wraps(function)
        def memoised_function(*args, **kwargs):
            return results()(*args, **kwargs)

        memoised_function.cache_clear = lambda: results().cache_clear()
        return memoised_function

    return decorate
