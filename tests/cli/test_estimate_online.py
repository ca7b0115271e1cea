"""``comanip estimate --online``: a recorded stream through the online estimator, one row per sample with its goal
and its forecast, and its mistakes."""

import csv
import json

import numpy as np
import pytest

import comanip
from comanip.cli.main import main
from tests.cli.test_cli_errors import assert_one_line_error, run_cli


@pytest.fixture(scope="module")
def observations(tmp_path_factory):
    """0.3 s at rest, then the planar model's own reach to (0.3, 0.1) m: a CSV of timestamped states, and the plan."""
    plan = comanip.Planner(comanip.presets.load("planar")).solve(np.zeros(4), [0.3, 0.1], 0.02)
    rest = np.arange(0.0, 0.3, 0.01)
    t = np.r_[rest, 0.3 + plan.t[1:]]
    states = np.r_[np.zeros((len(rest), 4)), plan.mean[1:, :4]]
    path = tmp_path_factory.mktemp("observations") / "reach.csv"
    with open(path, "w") as file:
        file.write("t_s,q0,q1,qdot0,qdot1\n")
        for ti, state in zip(t, states):
            file.write(",".join(f"{v:.9g}" for v in [ti, *state]) + "\n")
    return path, t, states


def test_every_sample_gets_a_row_and_the_reach_ends_on_its_goal(observations, tmp_path, capsys):
    """One row per sample; none has a goal while the hand rests before the reach; the last goal is the reach's within
    its width; the forecast 0.1 s on from mid-reach is nearer where the hand then was than the hand staying put."""
    path, t, states = observations
    out = tmp_path / "online"
    assert main(["estimate", "--online", "--observations", str(path), "--out", str(out), "--png"]) == 0, capsys.readouterr()
    with open(out / "online.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert len(rows) == len(t)
    assert all(row["status"] == "" for row in rows[:25])                    # at rest: no reach yet
    last = rows[-1]
    assert np.hypot(float(last["goal_x_m"]) - 0.3, float(last["goal_y_m"]) - 0.1) < 0.02
    mid = int(np.searchsorted(t, 0.3 + 0.25))
    ahead = int(np.searchsorted(t, t[mid] + 0.1))
    forecast = np.array([float(rows[mid]["forecast_0.1s_x_m"]), float(rows[mid]["forecast_0.1s_y_m"])])
    assert np.linalg.norm(forecast - states[ahead, :2]) < np.linalg.norm(states[mid, :2] - states[ahead, :2])
    saved = json.loads((out / "estimate.json").read_text())
    assert np.allclose(saved["goal"], [float(last["goal_x_m"]), float(last["goal_y_m"])])
    assert (out / "online.png").stat().st_size > 0


@pytest.mark.parametrize("argv, fragments", [
    (["--online"], ["--online streams --observations"]),
    (["--online", "--observations", "{obs}", "--candidates", "0.3,0;0.2,0.2"], ["--candidates does not go with --online"]),
    (["--online", "--observations", "{obs}", "--leads", "0.1,-0.2"], ["--leads must be times ahead > 0 s"]),
    (["--online", "--observations", "{obs}", "--prior", "0.3"], ["prior_goal must have shape (2,)"]),
    (["--online", "--observations", "{obs}", "--forecast-horizon", "-0.1"], ["--forecast-horizon must be a time ahead > 0 s"]),
    (["--online", "--observations", "{obs}", "--estimator", "nobody"], ["--estimator", "recorded", ".yaml"]),
])
def test_a_mistake_is_one_line_before_the_folder_is_made(argv, fragments, observations, tmp_path, capsys):
    out = tmp_path / "online"
    argv = [a.format(obs=observations[0]) for a in argv]
    assert_one_line_error(*run_cli(["estimate", *argv, "--out", str(out)], capsys), *fragments)
    assert not out.exists()


def test_the_forecast_horizon_is_one_option_and_bounds_the_path(observations, tmp_path, capsys):
    """Streamed up to mid-reach, the last estimate's path (what a robot follows) reaches
    --forecast-horizon seconds ahead, on the forecast; without it, on to where the forecast stops."""
    path, t, states = observations
    mid = tmp_path / "mid.csv"
    lines = path.read_text().splitlines()
    mid.write_text("\n".join(lines[:1 + int(np.searchsorted(t, 0.3 + 0.2))]) + "\n")
    paths = {}
    for name, extra in (("bounded", ["--forecast-horizon", "0.1"]), ("whole", [])):
        out = tmp_path / name
        assert main(["estimate", "--online", "--observations", str(mid), "--out", str(out), *extra]) == 0, capsys.readouterr()
        paths[name] = json.loads((out / "estimate.json").read_text())
    bounded, whole = paths["bounded"], paths["whole"]
    assert bounded["path"]["t_s"][-1] == pytest.approx(bounded["t_obs"] + 0.1, abs=1e-9)
    assert whole["path"]["t_s"][-1] > whole["t_obs"] + 0.2
    common = np.array(bounded["path"]["t_s"][:-1])
    np.testing.assert_allclose(np.array(bounded["path"]["position_m"])[:-1],
                               np.array(whole["path"]["position_m"])[:len(common)], atol=1e-12)
