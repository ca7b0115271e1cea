"""A planner per model (comanip.planning.planner_cache)."""

import comanip
from comanip.planning.planner import Planner
from comanip.planning.planner_cache import PlannerCache


def test_a_planner_cache_builds_one_planner_per_model():
    cache = PlannerCache(size=1)
    planner = cache.planner(comanip.presets.planar())
    assert isinstance(planner, Planner) and cache.planner(comanip.presets.planar().config()) is planner
