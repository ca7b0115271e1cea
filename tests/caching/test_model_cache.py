"""The one model-keyed cache (comanip.caching.model_cache) that planners and estimators are kept in."""

import comanip
from comanip.caching.model_cache import ModelCache
from comanip.model import model_key


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
