"""The planner an estimator builds for a model (the key that says two models are the same is
:func:`comanip.caching.model_cache.model_key`)."""

from __future__ import annotations

from comanip.model import ReachingModel
from comanip.planning.planner import Planner, SolverOptions


def checked_model(model) -> ReachingModel | Planner:
    """``model`` if it is a ReachingModel or a Planner; ValueError saying what it is otherwise."""
    if not isinstance(model, (ReachingModel, Planner)):
        raise ValueError(f"model must be a comanip.ReachingModel or Planner (e.g. comanip.presets.planar()), got {type(model).__name__}")
    return model


def estimation_planner(model: ReachingModel | Planner) -> Planner:
    """A new planner for ``model`` (a Planner passed in is returned as it is).

    Its terms are compiled to C (``SolverOptions(compile=True)``, cached on disk, built once per model): an
    estimate evaluates them many times, so compiled terms make it faster (docs/results/speed.md), where the
    planner's own default leaves point masses uncompiled for sweeps over many models.
    """
    if isinstance(checked_model(model), Planner):
        return model
    return Planner(model, SolverOptions(compile=True))
