"""Multi-component reaching: the dispersion profile, the closed-loop data generator, the transition GP, trends."""

import json
import warnings

import numpy as np
import pytest

import comanip
from comanip.cli.main import main
from comanip.multicomponent.perpendicular_dispersion import perpendicular_dispersion_profile
from comanip.multicomponent.transition_csv import (
    REQUIRED_COLUMNS,
    read_transition_csv,
    shipped_dataset_path,
    write_transition_csv,
)
from comanip.multicomponent.transition_data import generate_transition_data, simulate_paths
from comanip.multicomponent.transition_model import ExtrapolationWarning, TransitionModel
from comanip.multicomponent.trends import trend_report


# ---- the dispersion profile ----------------------------------------------------------------------------------

def test_dispersion_profile_matches_the_closed_form_of_synthetic_paths(rng):
    # paths along a tilted 3-D line with perpendicular offsets a_j sin(pi p / D): the dispersion over progress p
    # is exactly std(a) |sin(pi p / D)|, peaking at D / 2; time runs non-uniformly and the hands overshoot
    start, goal = np.array([0.1, -0.2, 0.3]), np.array([0.4, 0.2, 0.3])
    D = np.linalg.norm(goal - start)
    u = (goal - start) / D
    normal = np.array([-u[1], u[0], 0.0])
    amplitudes = rng.normal(0.0, 0.01, 25)
    s = np.sin(np.linspace(0, 1, 3000) ** 1.5 * np.pi / 2) * 1.05   # progress fraction: 0 → 1.05, back to 1.05·sin
    s = np.concatenate([s, 1.05 - 0.05 * np.linspace(0, 1, 200)])   # come back to the goal after the overshoot
    paths = np.array([start + np.outer(D * s, u) + np.outer(a * np.sin(np.pi * np.minimum(s, 1.0)), normal)
                      for a in amplitudes])
    profile = perpendicular_dispersion_profile(paths, goal, n_points=81)
    expected = np.std(amplitudes, ddof=1) * np.abs(np.sin(np.pi * profile.progress / D))
    np.testing.assert_allclose(profile.dispersion, expected, atol=2e-5)
    assert profile.transition_distance == pytest.approx(D / 2, abs=D / 400)
    assert profile.peak_dispersion == pytest.approx(np.std(amplitudes, ddof=1), rel=1e-3)
    assert profile.has_interior_peak


@pytest.mark.slow
def test_closed_loop_reacher_has_an_interior_dispersion_peak(planar_planner, rng):
    # SPEC §9: with replanning from the noisy state the spread across the path rises, then feedback corrects it
    D, w = 0.3, 0.02
    paths, settled, failed = simulate_paths(planar_planner, D, w, n_trials=12, steps=60, rng=rng)
    profile = perpendicular_dispersion_profile(paths, [D, 0.0])
    assert settled == 12 and failed == 0
    assert profile.has_interior_peak
    assert 0.2 * D < profile.transition_distance < 0.85 * D     # 12 trials: seeds gave 0.5–0.75 D
    assert profile.dispersion[-1] < 0.75 * profile.peak_dispersion   # and 0.25–0.65 of the peak left at the goal


@pytest.mark.slow
def test_generated_rows_do_not_depend_on_the_number_of_workers(tmp_path):
    kwargs = dict(distances_over_arm_length=[0.3], widths=[0.01, 0.04], n_trials=3, steps=40, seed=7, progress=False)
    serial = generate_transition_data(workers=1, **kwargs)
    parallel = generate_transition_data(workers=2, **kwargs)
    assert serial == parallel
    assert [r["width_m"] for r in serial] == [0.01, 0.04]
    path = write_transition_csv(serial, tmp_path / "rows.csv", metadata={"seed": 7})
    back = read_transition_csv(path)
    np.testing.assert_allclose(back["transition_distance_m"], [r["transition_distance_m"] for r in serial], rtol=1e-5)
    assert json.loads(path.with_suffix(".json").read_text()) == {"seed": 7}


def test_generate_and_fit_with_a_preset_yaml_of_a_model_with_activation_stages(tmp_path, capsys):
    # the person of --preset (here planar with two 40 ms activation stages, state (8,)) makes the data, the JSON
    # records it and fit names it; w ≥ 0.04 because at H = 30 this model stays still for w ≤ 0.02
    preset = comanip.presets.save(comanip.presets.planar().replace(activation=(0.04, 0.04), name="planar_activation"),
                                  tmp_path / "planar_activation.yaml")
    csv = tmp_path / "data.csv"
    assert main(["transition", "generate", "--preset", str(preset), "--distances", "0.3,0.43", "--widths", "0.04,0.05",
                 "--trials", "3", "--steps", "30", "--workers", "1", "--out", str(csv)]) == 0
    capsys.readouterr()
    metadata = json.loads(csv.with_suffix(".json").read_text())
    assert metadata["model"]["activation"] == [0.04, 0.04] and metadata["model"]["name"] == "planar_activation"
    rows = read_transition_csv(csv)
    assert len(rows["width_m"]) == 4 and np.all(rows["failed_replans"] == 0)
    assert np.all((rows["transition_distance_m"] > 0) & (rows["transition_distance_m"] < 0.43 * 0.7))
    assert main(["transition", "fit", "--data", str(csv), "--out", str(tmp_path / "fit"), "--verbose"]) == 0
    assert json.loads(capsys.readouterr().out)["data_made_by"]["model"] == "planar_activation"


def test_generate_rejects_an_arm_before_any_work():
    with pytest.raises(ValueError, match="must be a point-mass model .* an arm"):
        generate_transition_data([0.3], [0.02], 3, model=comanip.presets.franka(), progress=False)


# ---- the Gaussian process ------------------------------------------------------------------------------------

def _known_function(ratio, width):
    return 0.25 * ratio + 0.05 * np.sin(4 * ratio) - 1.5 * width


@pytest.fixture(scope="module")
def synthetic_model():
    rng = np.random.default_rng(3)
    ratio, width = rng.uniform(0.2, 0.8, 60), rng.uniform(0.005, 0.05, 60)
    return TransitionModel((ratio, width, _known_function(ratio, width) + rng.normal(0, 0.002, 60)))


def test_gp_recovers_a_known_smooth_function_from_noisy_samples(synthetic_model):
    R, W = np.meshgrid(np.linspace(0.25, 0.75, 9), np.linspace(0.01, 0.045, 9))
    mean, std = synthetic_model.predict_normalised(R, W)
    error = mean - _known_function(R, W)
    assert np.max(np.abs(error)) < 0.003                     # well inside the 2 mm sample noise, everywhere
    assert np.mean(np.abs(error) < 3 * std) > 0.9             # and its std is honest about the rest
    assert 0.001 < synthetic_model.noise_std < 0.004          # the fitted noise is the 2 mm that was added


def test_gp_std_grows_away_from_the_data(synthetic_model):
    ratios = np.array([0.5, 0.9, 1.2, 1.6, 2.2])
    with pytest.warns(ExtrapolationWarning):
        _, std = synthetic_model.predict_normalised(ratios, 0.02)
    assert np.all(np.diff(std) > 0)
    assert std[-1] > 10 * std[0]


def test_predict_in_metres_divides_by_the_arm_length(synthetic_model):
    mean_m, std_m = synthetic_model.predict(0.35, 0.02)
    mean_r, std_r = synthetic_model.predict_normalised(0.35 / synthetic_model.arm_length, 0.02)
    assert (mean_m, std_m) == (mean_r, std_r)


def test_saved_model_reloads_with_the_same_posterior(synthetic_model, tmp_path):
    path = synthetic_model.save(tmp_path / "model.json")
    assert json.loads(path.read_text())["kind"] == "comanip.TransitionModel"
    again = TransitionModel.load(path)
    R, W = np.meshgrid(np.linspace(0.1, 1.0, 5), np.linspace(0.002, 0.06, 5))
    for a, b in zip(synthetic_model.posterior(R.ravel(), W.ravel()), again.posterior(R.ravel(), W.ravel())):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-14)


# ---- bad input -----------------------------------------------------------------------------------------------

def _write_csv(path, header, rows):
    path.write_text(",".join(header) + "\n" + "\n".join(",".join(str(v) for v in row) for row in rows) + "\n")
    return path


def test_csv_with_a_missing_column_is_rejected_by_name(tmp_path):
    path = _write_csv(tmp_path / "lab.csv", ["distance_over_arm_length", "width_m"], [[0.3, 0.01]] * 4)
    with pytest.raises(ValueError, match="transition_distance_m"):
        TransitionModel(path)


def test_negative_widths_and_nan_in_the_data_are_rejected(tmp_path):
    header = list(REQUIRED_COLUMNS)
    negative = _write_csv(tmp_path / "neg.csv", header, [[0.3, 0.01, 0.1], [0.4, -0.02, 0.1], [0.5, 0.02, 0.2]])
    with pytest.raises(ValueError, match=r"width_m.*> 0.*row 1"):
        TransitionModel(negative)
    missing = _write_csv(tmp_path / "nan.csv", header, [[0.3, 0.01, 0.1], [0.4, 0.02, ""], [0.5, 0.02, 0.2]])
    with pytest.raises(ValueError, match="transition_distance_m.*NaN"):
        TransitionModel(missing)


def test_bad_queries_are_rejected_and_extrapolation_is_stated(synthetic_model):
    with pytest.raises(ValueError, match="distance must be finite"):
        synthetic_model.predict(np.nan, 0.02)
    with pytest.raises(ValueError, match="width must be > 0"):
        synthetic_model.predict(0.3, -0.01)
    with pytest.warns(ExtrapolationWarning, match=r"D/L from 1\.5.*1\.05 m at L = 0\.7 m.*range \[0\.2"):
        synthetic_model.predict(1.05, 0.02)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        synthetic_model.predict(0.35, 0.02)                  # inside the data: no warning
    with pytest.raises(ValueError, match="not fitted"):
        TransitionModel(data=None).predict(0.3, 0.02)


# ---- the shipped data and the published trends -------------------------------------------------------------

@pytest.fixture(scope="module")
def shipped_model():
    return comanip.TransitionModel()


def test_shipped_data_and_model_against_the_published_trends(shipped_model):
    # docs/results/calibration.md states these verdicts; a regenerated dataset must keep them in step
    report = {(t["input"], t["output"]): t for t in trend_report(shipped_model)["trends"]}
    farther = report[("distance_over_arm_length", "transition_distance_m")]
    assert farther["data"]["verdict"] == "reproduced" and farther["model"]["verdict"] == "reproduced"
    assert report[("distance_over_arm_length", "peak_dispersion_m")]["data"]["verdict"] == "reproduced"
    assert report[("width_m", "peak_dispersion_m")]["data"]["verdict"] == "reproduced"
    # not reproduced: a larger goal does not move the simulated person's peak closer to the goal
    closer = report[("width_m", "transition_distance_m")]
    assert closer["data"]["verdict"] == "not significant" and closer["model"]["verdict"] == "not significant"
    # and the model's predicted transition distance grows with D/L at every width of the data
    ratios = np.linspace(*shipped_model.data_range["distance_over_arm_length"], 7)
    for width in np.unique(shipped_model.training_data["width_m"]):
        mean, _ = shipped_model.predict_normalised(ratios, width)
        assert np.all(np.diff(mean) > 0)


def test_transition_commands_fit_save_and_plot(tmp_path, capsys):
    assert main(["transition", "fit", "--out", str(tmp_path), "--verbose"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["rows"] == len(read_transition_csv(shipped_dataset_path())["width_m"])
    assert printed["data_made_by"] == {"model": "planar",
                                       "command": "comanip transition generate --out src/comanip/data/transition_planar.csv"}
    saved = TransitionModel.load(tmp_path / "model.json")
    assert saved.predict(0.3, 0.02) == comanip.TransitionModel().predict(0.3, 0.02)
    assert json.loads((tmp_path / "trends.json").read_text()) == printed["trends"]
    figure = tmp_path / "fig2.png"
    assert main(["transition", "plot", "--model", str(tmp_path / "model.json"), "--out", str(figure)]) == 0
    assert figure.stat().st_size > 10_000
