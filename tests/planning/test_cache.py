"""The one model-keyed cache (comanip.caching.model_cache) that planners and estimators are kept in."""

import comanip
from comanip.caching.model_cache import ModelCache
from comanip.model import model_key
from comanip.planning.planner_cache import PlannerCache
from comanip.planning.planner import Planner


def test_models_with_equal_parameters_share_an_entry_and_the_oldest_is_dropped():
    built = []
    cache = ModelCache(lambda model: built.append(model) or len(built), size=2)
    planar = comanip.presets.planar()
    assert cache.get(planar) == cache.get(comanip.presets.planar()) == cache.get(planar.config()) == 1
    assert cache.get(planar.replace(description="another text")) == 1  # the description is not a parameter
    assert cache.get(planar.replace(kappa=3e-2)) == 2
    assert cache.get(planar.replace(H=20)) == 3
    assert len(cache) == 2 and cache.get(planar) == 4  # planar was the least recently used, so it was dropped
    assert model_key(planar) != model_key(planar.replace(kappa=3e-2))


def test_a_planner_cache_builds_one_planner_per_model():
    cache = PlannerCache(size=1)
    planner = cache.planner(comanip.presets.planar())
    assert isinstance(planner, Planner) and cache.planner(comanip.presets.planar().config()) is planner
