"""Solvers and functions built once per reaching model and shared by every estimate and posterior of it."""

from __future__ import annotations

import json
from collections import OrderedDict

import casadi as ca

from comanip.belief.propagation import linearised_step_function
from comanip.model import ReachingModel
from comanip.planning.planner import Planner, SolverOptions

#: How many models keep a built planner at once (least recently used dropped first).
CACHE_SIZE = 4

_planners: OrderedDict[str, Planner] = OrderedDict()
_step_jacobians: OrderedDict[str, ca.Function] = OrderedDict()


def model_key(model: ReachingModel) -> str:
    """A key equal for models with equal parameters (two loads of one preset share it)."""
    config = model.config()
    config.pop("description", None)
    return json.dumps(config, sort_keys=True)


def shared_planner(model: ReachingModel | Planner) -> Planner:
    """The planner of ``model``, built on first use; a Planner passed in is returned as it is.

    Its terms are compiled to C (``SolverOptions(compile=True)``, cached on disk; a first build costs
    2–9 s for a point mass): an estimate evaluates them some fifteen times, and compiled they make a warm
    Cartesian estimate about a third faster (benchmarks/README.md), where the planner's own default
    leaves point masses uncompiled for sweeps over many models.
    """
    if isinstance(model, Planner):
        return model
    if not isinstance(model, ReachingModel):
        raise ValueError(f"model must be a comanip.ReachingModel or Planner (e.g. comanip.presets.planar()), got {type(model).__name__}")
    return cached_per_model(_planners, model, lambda m: Planner(m, SolverOptions(compile=True)))


def shared_step_jacobians(model: ReachingModel) -> ca.Function:
    """The body's linearised step ``(s, tau) -> (f, A, B)`` (see :func:`comanip.belief.linearised_step_function`)."""
    return cached_per_model(_step_jacobians, model, lambda m: linearised_step_function(m.body, m.h))


def cached_per_model(cache: OrderedDict, model: ReachingModel, build):
    """cache[model] (an OrderedDict keyed by :func:`model_key`), built by build(model) on first use; least recently used dropped."""
    key = model_key(model)
    if key not in cache:
        cache[key] = build(model)
        while len(cache) > CACHE_SIZE:
            cache.popitem(last=False)
    cache.move_to_end(key)
    return cache[key]
