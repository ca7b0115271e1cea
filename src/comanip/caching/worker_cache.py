"""A :class:`~comanip.caching.model_cache.ModelCache` owned by each Dask worker: Dask's counterpart of a process
pool's initializer. Imported only where Dask is used (it imports ``distributed``)."""

from __future__ import annotations

from typing import Callable

from comanip.caching.model_cache import ModelCache
from comanip.extras import require

distributed = require("distributed", "sweeps")


class WorkerCache(distributed.WorkerPlugin):
    """Registered on a cluster (``client.register_plugin(WorkerCache(...))``), gives every worker, present
    or joining later, its own ``ModelCache(build, size)``; a task on a worker reaches it with
    :func:`worker_cache`. ``build`` must be picklable (a module-level function or a class)."""

    def __init__(self, name: str, build: Callable, size: int):
        self.name = name
        self.build = build
        self.size = size
        self.cache: ModelCache | None = None

    def setup(self, worker) -> None:
        self.cache = ModelCache(self.build, self.size)


def worker_cache(name: str) -> ModelCache:
    """The cache the :class:`WorkerCache` called ``name`` gave the worker running this task."""
    return distributed.get_worker().plugins[name].cache
