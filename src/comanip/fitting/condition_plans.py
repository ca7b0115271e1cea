"""Planning (or executing in closed loop) every condition of a fit for one model configuration, here or on a Dask
cluster.

Tasks carry the model as its config (plain data), never a Planner: planners are kept by their model's
parameters in a cache that the ConditionPlanner owns (planning here) or that each Dask worker owns (a
:class:`~comanip.caching.worker_cache.WorkerCache` registered on the cluster), so a process builds a
Planner once per configuration and reuses it for every condition.

Every solve is cold (the planner's multi-start from minimum-jerk guesses), not warm-started from the
previous evaluation's plan, so that the objective is a function of the parameters alone and the fitted
model predicts what ``Planner(model).solve`` gives: the planning problem has several local optima, and a solve
warm-started from another parameter value's plan can stay in a different one, which would make the objective
depend on the optimiser's path.
"""

from __future__ import annotations

import threading

import numpy as np

from comanip.analysis.speed_profile import ReachTiming
from comanip.arguments import as_scheduler_address
from comanip.fitting.closed_loop_timing import closed_loop_timing
from comanip.model import ReachingModel
from comanip.caching.model_cache import ModelCache
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner
from comanip.planning.solver_options import SolverOptions


_PLANNERS = "comanip-condition-planners"
"""The name of the WorkerCache that gives each Dask worker its planners."""

_CACHE_SIZE = 2
"""Planners a cache keeps (a fit alternates between few configurations at a time)."""


def locked_planner(model: ReachingModel) -> tuple[Planner, threading.Lock]:
    """A Planner for ``model`` and the lock that serialises its solves (a Planner is not thread-safe, and a
    Dask worker may run tasks in threads). A fit's planner serves one parameter set, so it is never compiled to C:
    compiling takes seconds for every new model, more than the planner solves."""
    return Planner(model, SolverOptions(compile=False)), threading.Lock()


def plan_condition(planners: ModelCache, model_config: dict, start: np.ndarray, goal: np.ndarray,
                   width: float) -> Plan:
    """One reach, solved cold with the planner ``planners`` (a cache of :func:`locked_planner`) holds for the
    model given as its config: start state (2n,), goal (d,) m, width m."""
    planner, lock = planners.get(model_config)
    with lock:
        return planner.solve(start, goal, width)


def time_condition(planners: ModelCache, model_config: dict, start: np.ndarray, goal: np.ndarray, width: float,
                   executions: int, seed: int) -> ReachTiming:
    """The timing of one condition's mean closed-loop reach (:func:`~comanip.fitting.closed_loop_timing.closed_loop_timing`)
    with the planner ``planners`` holds for the model given as its config."""
    planner, lock = planners.get(model_config)
    with lock:
        return closed_loop_timing(planner, start, goal, width, executions, seed)


def _plan_on_worker(model_config: dict, start: np.ndarray, goal: np.ndarray, width: float) -> Plan:
    """:func:`plan_condition` on a Dask worker, with the worker's planners."""
    from comanip.caching.worker_cache import worker_cache

    return plan_condition(worker_cache(_PLANNERS), model_config, start, goal, width)


def _time_on_worker(model_config: dict, start: np.ndarray, goal: np.ndarray, width: float, executions: int,
                    seed: int) -> ReachTiming:
    """:func:`time_condition` on a Dask worker, with the worker's planners."""
    from comanip.caching.worker_cache import worker_cache

    return time_condition(worker_cache(_PLANNERS), model_config, start, goal, width, executions, seed)


class ConditionPlanner:
    """Plans a fixed list of reaches for any model configuration; use as a context manager.

    Args:
        reaches: (start state (2n,), goal (d,) m, width m) per condition.
        scheduler: None plans in this process; a Dask scheduler address ("tcp://host:8786") or a
            ``dask.distributed.Client`` maps the conditions onto that cluster (an address's client is
            closed on exit, a given client is left open).
    """

    def __init__(self, reaches: list[tuple[np.ndarray, np.ndarray, float]], scheduler=None):
        self.reaches = reaches
        self._client, self._owned = _client(scheduler)
        self._planners = ModelCache(locked_planner, _CACHE_SIZE)
        if self._client is not None:
            from comanip.caching.worker_cache import WorkerCache

            self._client.register_plugin(WorkerCache(_PLANNERS, locked_planner, _CACHE_SIZE))

    def __enter__(self) -> "ConditionPlanner":
        return self

    def __exit__(self, *exc) -> None:
        if self._owned:
            self._client.close()

    def plans(self, model: ReachingModel) -> list[Plan]:
        """One plan per reach for this model, in the order of ``reaches``; never raises on a failed solve."""
        config = model.config()
        tasks = [(config, start, goal, width) for start, goal, width in self.reaches]
        if self._client is None:
            return [plan_condition(self._planners, *task) for task in tasks]
        return self._client.gather(self._client.map(_plan_on_worker, *zip(*tasks), pure=False))

    def timings(self, model: ReachingModel, executions: int, seed: int) -> list[ReachTiming]:
        """The timing of each reach's mean closed-loop reach for this model, in the order of ``reaches``."""
        config = model.config()
        tasks = [(config, start, goal, width, executions, seed) for start, goal, width in self.reaches]
        if self._client is None:
            return [time_condition(self._planners, *task) for task in tasks]
        return self._client.gather(self._client.map(_time_on_worker, *zip(*tasks), pure=False))


def _client(scheduler):
    """(Dask client or None, whether this object owns it) for a scheduler argument."""
    if scheduler is None:
        return None, False
    from comanip.extras import require

    Client = require("dask.distributed", "sweeps").Client

    if isinstance(scheduler, Client):
        return scheduler, False
    as_scheduler_address("scheduler (or None, or a dask.distributed.Client)", scheduler)
    try:
        return Client(scheduler, timeout="10s"), True
    except (OSError, TimeoutError) as error:
        raise ValueError(f"could not connect to the Dask scheduler at {scheduler!r} ({type(error).__name__})") from None
