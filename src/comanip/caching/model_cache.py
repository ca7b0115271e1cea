"""Objects built from a model and kept by the model's parameters: one cache class, one key.

A :class:`ModelCache` holds what is costly to build for a model (a Planner, a GoalEstimator) and hands the
same object back for a model with the same parameters (:func:`model_key`: two loads of one preset, or a
model rebuilt from its JSON config in a worker process, share it). Whoever needs reuse owns a cache: a
caller, an object such as ``ConditionPlanner``, or a worker process (set up by its pool's initializer).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Callable, Generic, Hashable, TypeVar

from comanip.model import ReachingModel, config_key, model_key

T = TypeVar("T")


class ModelCache(Generic[T]):
    """Objects ``build(model)`` kept by the model's parameters, the least recently used dropped first.

    ``get`` takes a ReachingModel or its ``config()`` dict (a model is rebuilt from the dict only when
    nothing is cached for it). At most ``size`` objects are kept. Safe to share between threads (an object
    is built under the cache's lock); the objects themselves may not be.
    """

    def __init__(self, build: Callable[[ReachingModel], T], size: int = 4):
        self.build = build
        self.size = size
        self._items: OrderedDict[Hashable, T] = OrderedDict()
        self._lock = threading.Lock()

    def key(self, model) -> Hashable:
        """The key of ``model`` (a ReachingModel or its config dict)."""
        return config_key(model) if isinstance(model, dict) else model_key(model)

    def get(self, model) -> T:
        """The object for ``model`` (a ReachingModel or its config dict), built on first use."""
        return self._get(self.key(model), model)

    def _get(self, key: Hashable, model) -> T:
        with self._lock:
            if key not in self._items:
                built = ReachingModel.from_config(model) if isinstance(model, dict) else model
                self._items[key] = self.build(built)
                while len(self._items) > self.size:
                    self._items.popitem(last=False)
            self._items.move_to_end(key)
            return self._items[key]

    def __len__(self) -> int:
        return len(self._items)
