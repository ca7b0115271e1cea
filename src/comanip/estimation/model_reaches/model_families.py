"""A model's reach families, built once and kept between online estimators (:class:`FamilyCache`)."""

from __future__ import annotations

from comanip.caching.model_cache import ModelCache
from comanip.caching.process_caches import PROCESS_CACHES
from comanip.estimation.model_reaches.estimation_planner import checked_model, estimation_planner
from comanip.estimation.model_reaches.reach_family import ReachFamily
from comanip.model import ReachingModel
from comanip.planning.planner import Planner


class ModelFamilies:
    """A model's planner and its reach families, one per width and family grid."""

    def __init__(self, model: ReachingModel | Planner):
        self.planner = estimation_planner(model)
        self._families: dict[tuple, ReachFamily] = {}

    def family(self, width: float, distances: tuple[float, float], size: int, tolerance: float) -> ReachFamily:
        """The family of reaches of goal width ``width`` (m) over ``distances`` (D_min, D_max) m, from ``size``
        members, interpolated within ``tolerance`` m (:class:`~comanip.estimation.model_reaches.reach_family.ReachFamily`)."""
        key = (float(width), tuple(distances), int(size), float(tolerance))
        if key not in self._families:
            self._families[key] = ReachFamily(self.planner, width, *key[1:])
        return self._families[key]


class FamilyCache(ModelCache[ModelFamilies]):
    """Reach families kept between online estimators: by the model's parameters (a Planner is its own key)."""

    def __init__(self, size: int = 4):
        super().__init__(ModelFamilies, size)

    def key(self, model):
        return model if isinstance(model, Planner) else super().key(model)

    def families(self, model: ReachingModel | Planner) -> ModelFamilies:
        return self.get(checked_model(model))


def default_families() -> FamilyCache:
    """The reach-family cache of this process (:data:`comanip.caching.process_caches.PROCESS_CACHES`), which an
    online estimator given none uses."""
    return PROCESS_CACHES.get("reach families", FamilyCache)
