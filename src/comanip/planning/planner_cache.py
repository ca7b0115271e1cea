"""Planners kept by their model's parameters (:class:`PlannerCache`, a :class:`~comanip.caching.model_cache.ModelCache`)."""

from __future__ import annotations

from comanip.caching.model_cache import ModelCache
from comanip.planning.planner import Planner
from comanip.planning.solver_options import SolverOptions


class PlannerCache(ModelCache[Planner]):
    """Planners kept by their model's parameters, all built with the same ``options``."""

    def __init__(self, size: int = 4, options: SolverOptions | None = None):
        super().__init__(lambda model: Planner(model, options), size)

    def planner(self, model) -> Planner:
        """The planner for ``model`` (a ReachingModel or its config dict), built on first use."""
        return self.get(model)
