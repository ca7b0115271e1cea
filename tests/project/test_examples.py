"""Every script in examples/ runs, at its small size, and saves its figure; the example inputs in
examples/data/ read back in the formats docs/data_formats.md describes and are the ones their generator writes.

Each example runs in its own process, as a user runs it (``python examples/NAME.py``), with
COMANIP_EXAMPLES_SMALL=1 (the smallest run that shows the concept), MPLBACKEND=Agg and its figures in a
temporary folder.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
SCRIPTS = sorted(path for path in EXAMPLES.glob("*.py") if not path.name.startswith("_"))
NEEDS_ROS = {"ros_node_replay.py"}
NEEDS_DATA = {"predict_recorded_reaches.py"}


def test_there_are_five_to_eight_examples():
    assert 5 <= len(SCRIPTS) <= 8, [path.name for path in SCRIPTS]


@pytest.mark.parametrize("script", SCRIPTS, ids=[path.stem for path in SCRIPTS])
def test_example_runs_and_saves_its_figure(script, tmp_path):
    if script.name in NEEDS_ROS and importlib.util.find_spec("rclpy") is None:
        pytest.skip("needs the ros extra (pip install -e '.[ros]')")
    if script.name in NEEDS_DATA and importlib.util.find_spec("cursory") is None:
        pytest.skip("needs the data extra (pip install -e '.[data]')")
    env = {**os.environ, "COMANIP_EXAMPLES_SMALL": "1", "COMANIP_EXAMPLES_OUT": str(tmp_path), "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "src"), os.environ.get("PYTHONPATH")]))}
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, f"{script.name} failed:\n{run.stdout[-2000:]}\n{run.stderr[-3000:]}"
    figure = tmp_path / f"{script.stem}.png"
    assert figure.is_file() and figure.stat().st_size > 10_000, f"{script.name} saved no figure"


def test_every_example_says_what_it_shows_and_how_to_run_it():
    for script in SCRIPTS:
        text = script.read_text(encoding="utf-8")
        assert text.startswith('"""'), f"{script.name} has no docstring"
        assert f"python examples/{script.name}" in text.split('"""')[1], f"{script.name}: no run line in its docstring"
        assert "savefig" in text, f"{script.name} draws no figure"


def test_the_example_inputs_read_in_their_documented_formats():
    import comanip
    from comanip.recordings.observation_files import read_observations
    from comanip.fitting import load_recordings
    from comanip.ros.node_settings import NodeSettings

    data = EXAMPLES / "data"
    times, states = read_observations(data / "observations.csv", 2)
    assert times[0] == 0 and states.shape == (len(times), 4)
    trials = load_recordings(data / "recordings")
    assert len(trials) == 6 and all(trial.position.shape[1] == 2 for trial in trials)
    settings = NodeSettings.from_yaml(data / "node.yaml")
    assert settings.model().name == comanip.presets.cartesian().name
    times, states = read_observations(data / "hand.csv", 3)
    assert states.shape == (len(times), 6) and abs(times[1] - times[0] - 0.01) < 1e-9


def test_the_example_inputs_are_what_their_generator_writes(tmp_path, monkeypatch):
    """make_example_data.py rebuilds the shipped inputs (to the printed six digits), so they can be regenerated."""
    spec = importlib.util.spec_from_file_location("make_example_data", EXAMPLES / "data" / "make_example_data.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "HERE", tmp_path)
    module.write_observations()
    module.write_hand()
    import numpy as np

    for name in ("observations.csv", "hand.csv"):
        made, shipped = (np.loadtxt(folder / name, delimiter=",", skiprows=1) for folder in (tmp_path, EXAMPLES / "data"))
        np.testing.assert_allclose(made, shipped, rtol=1e-5, atol=1e-9, err_msg=f"{name} differs from its generator's")
