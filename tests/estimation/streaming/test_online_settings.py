"""One description of online estimation: the shipped descriptions load and survive YAML, bad settings are one-line
errors naming the setting, every front end builds its estimator in the one place, and the loop of a stream whose
reach is known updates on the grid of that reach."""

import ast
import dataclasses
from pathlib import Path

import numpy as np
import pytest

import comanip
from comanip.estimation import LoopSettings, OnlineOptions, OnlineSettings
from comanip.estimation.streaming import online_settings

SOURCE = Path(comanip.__file__).parent
BUILDER = SOURCE / "estimation" / "streaming" / "online_settings.py"


@pytest.mark.parametrize("name", online_settings.names())
def test_every_shipped_description_survives_yaml(name, tmp_path):
    settings = online_settings.load(name)
    again = online_settings.load(settings.save(tmp_path / f"{name}.yaml"))
    assert again == settings


def test_the_descriptions_say_whom_they_expect():
    recorded, correcting, robot = (online_settings.load(name) for name in ("recorded", "correcting", "sync_robot"))
    assert recorded.options == OnlineOptions()
    assert correcting.options.correction_time > 0 and correcting.options.led_axes == ()
    assert robot.options.led_axes == (2,) and robot.loop.segmentation is None and robot.prior_std == 0.25
    assert dataclasses.replace(robot.options, led_axes=(), led_deviation_time=correcting.options.led_deviation_time,
                               led_from=0.0, covariance_scale=1.0) == correcting.options


@pytest.mark.parametrize("values, fragment", [
    ({"modle": "cartesian"}, "unknown online settings setting(s) ['modle']"),
    ({"options": {"timing": "later"}}, "timing must be one of"),
    ({"options": {"people_model": "x"}}, "unknown options setting(s) ['people_model']"),
    ({"loop": {"rate": -5}}, "rate"),
    ({"loop": {"segmentation": {"radius": 0}}}, "radius"),
    ({"model": "no-such-model"}, "model: preset must be one of"),
    ({"width": -0.01}, "width"),
    ({"prior_std": "wide"}, "prior_std"),
    ({"forecast_leads": [0.1, -0.2]}, "forecast_leads must be times ahead > 0 s"),
    ({"options": {"forecast_horizon": 0}}, "forecast_horizon"),
    ({"loop": [1, 2]}, "loop must be a mapping"),
])
def test_a_bad_setting_is_one_line_naming_it(values, fragment):
    with pytest.raises(ValueError) as error:
        OnlineSettings.from_mapping(values)
    assert fragment in str(error.value) and "\n" not in str(error.value)


def test_an_unknown_description_lists_the_shipped_ones(tmp_path):
    with pytest.raises(ValueError, match="recorded"):
        online_settings.load("nobody")
    broken = tmp_path / "broken.yaml"
    broken.write_text("options: [unclosed\n")
    with pytest.raises(ValueError, match="not a readable YAML"):
        online_settings.load(broken)


def builds_an_estimator(tree: ast.AST) -> list[int]:
    """Lines of ``tree`` that call OnlineGoalEstimator (by name or attribute)."""
    return [node.lineno for node in ast.walk(tree) if isinstance(node, ast.Call)
            and getattr(node.func, "id", getattr(node.func, "attr", None)) == "OnlineGoalEstimator"]


def test_one_place_builds_an_online_estimator():
    """Every front end (node, simulated robots, handover, demo, command line, ReachStream) builds its estimator from a
    description: only OnlineSettings.estimator calls the estimator's constructor."""
    places = [f"{path.relative_to(SOURCE)}:{line}" for path in sorted(SOURCE.rglob("*.py"))
              for line in builds_an_estimator(ast.parse(path.read_text(encoding="utf-8")))]
    assert places == [f"{BUILDER.relative_to(SOURCE)}:{builds_an_estimator(ast.parse(BUILDER.read_text()))[0]}"], places


def test_a_second_place_is_found():
    planted = "import comanip\n\ndef mine(model):\n    return comanip.OnlineGoalEstimator(model, [0, 0])\n"
    assert builds_an_estimator(ast.parse(planted)) == [4]


def test_a_stream_begun_at_its_clock_updates_on_its_grid(cartesian_planner):
    """A reach begun at t = 0 and fed every 10 ms with a 50 ms rate: updates at 50, 100, ... ms from the clock, whatever
    the first sample's time; the estimator starts where the reach was begun."""
    settings = OnlineSettings(loop=LoopSettings(segmentation=None, rate=20.0))
    loop = settings.estimation_loop(model=cartesian_planner)
    start = np.array([0.1, 0.0, 0.2])
    loop.begin(0.0, start)
    due = []
    for t in np.arange(0.03, 0.5, 0.01):
        s = min(t / 0.5, 1.0)
        loop.add_sample(t, start + np.array([0.2, 0.1, 0.0]) * (10 * s**3 - 15 * s**4 + 6 * s**5), np.array([0.4, 0.2, 0.0]) * (30 * s**2 - 60 * s**3 + 30 * s**4))
        update = loop.take_due()
        if update is not None:
            due.append(round(update.t, 6))
            loop.estimate(update)
    assert due[:4] == [0.05, 0.1, 0.15, 0.2]
    np.testing.assert_array_equal(loop.estimator.start_position, start)
