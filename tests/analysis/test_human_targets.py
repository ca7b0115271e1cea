"""The human-likeness targets: the closed-form hit rate, the profile-shape metrics on
synthetic profiles, the verdict on the planar preset, and their place in ``comanip validate``."""

import json

import numpy as np
import pytest
from scipy.stats import ncx2

import comanip
from comanip.analysis import (
    ball_probability,
    measure_human_targets,
    minimum_jerk_speed_fraction,
    minimum_jerk_velocity,
    open_loop_grid,
    profile_shape,
    speed_metrics,
)
from comanip.cli.main import main
from comanip.validation import ValidationSettings, run_validation
from comanip.plots.validation_figures import HUMAN_FIGURE, draw_human_targets_figure
from comanip.validation.human_section import run_human_section
from comanip.validation.markdown import human_targets_markdown
from comanip.validation.run import _plain

DISTANCES = (0.15, 0.3, 0.45)
WIDTHS = (0.005, 0.01, 0.02, 0.04)


def _rotated(stds, angle):
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    return R @ np.diag(np.square(stds)) @ R.T


@pytest.mark.parametrize("mean, cov, radius", [
    ([0.0, 0.0], np.diag([1e-4, 1e-4]), 0.01),                      # isotropic, centred
    ([0.004, -0.002], _rotated([8e-3, 2e-3], 0.6), 0.01),           # anisotropic, rotated, off centre
    ([0.012, 0.0], _rotated([3e-3, 1.5e-2], -0.3), 0.02),           # off centre by more than the spread along it
    ([0.002, 0.0], np.diag([9e-6, 0.0]), 0.005),                    # singular: spread along the reach only
    ([0.006, 0.001, -0.002], np.diag([6e-5, 1e-5, 2e-6]), 0.01),    # 3-D anisotropic
])
def test_closed_form_hit_rate_agrees_with_monte_carlo(mean, cov, radius, rng):
    samples = rng.multivariate_normal(mean, cov, 200_000)
    monte_carlo = np.mean(np.linalg.norm(samples, axis=1) <= radius)
    assert ball_probability(mean, cov, radius) == pytest.approx(monte_carlo, abs=0.02)


def test_isotropic_hit_rate_is_the_noncentral_chi_square_cdf():
    mean, variance, radius = np.array([0.004, 0.003, -0.001]), 4e-5, 0.01
    exact = ncx2.cdf(radius**2 / variance, 3, mean @ mean / variance)
    assert ball_probability(mean, variance * np.eye(3), radius) == pytest.approx(exact, abs=1e-7)


@pytest.mark.parametrize("cov, word", [(np.eye(3), "shape"), (np.array([[1.0, 0.0], [0.0, -1.0]]), "semi-definite")])
def test_hit_rate_rejects_bad_covariances(cov, word):
    with pytest.raises(ValueError, match=word):
        ball_probability([0.0, 0.0], cov, 0.01)


T = np.arange(0.0, 1.2001, 0.01)


def _minimum_jerk(distance, movement_time, t=T):
    """Velocity (len(t), 2) m/s of a minimum-jerk reach along x with this SPEC §6 movement time (s)."""
    return minimum_jerk_velocity([0.0, 0.0], [distance, 0.0], movement_time, t)


def test_minimum_jerk_profile_passes_the_shape_metrics():
    velocity = _minimum_jerk(0.3, 0.8)
    shape = profile_shape(T, velocity, [1.0, 0.0])
    assert shape.onset == pytest.approx(float(minimum_jerk_speed_fraction(0.05, 0.8)), abs=1e-3)
    assert shape.onset < 0.06 and shape.peaks == 1 and shape.reversal == 0.0 and shape.end_speed < 0.05
    assert speed_metrics(T, np.linalg.norm(velocity, axis=1)).asymmetry == pytest.approx(0.532, abs=0.01)


def test_a_step_start_fails_the_onset_test():
    velocity = _minimum_jerk(0.3, 0.8, T + 0.3)   # already moving fast one sample after the start
    velocity[0] = 0.0
    shape = profile_shape(T, velocity, [1.0, 0.0])
    assert shape.onset > 0.5 and shape.peaks == 1 and shape.reversal == 0.0


def test_an_overshoot_and_return_fails_the_reversal_test_and_shows_a_second_peak():
    out = _minimum_jerk(0.33, 0.6)
    back = _minimum_jerk(-0.03, 0.3, T - 0.7) * (T >= 0.7)[:, None]
    shape = profile_shape(T, out + back, [1.0, 0.0])
    assert shape.reversal < -0.1 and shape.peaks == 2


def test_a_ripple_below_the_peak_floor_is_not_a_peak():
    bump = np.exp(-0.5 * ((T - 1.0) / 0.03) ** 2)[:, None] * [0.05, 0.0]   # 5 % of a 1 m/s peak, late
    velocity = _minimum_jerk(0.3, 0.8)
    velocity = velocity / np.linalg.norm(velocity, axis=1).max()
    assert profile_shape(T, velocity + bump, [1.0, 0.0]).peaks == 1
    assert profile_shape(T, velocity + bump, [1.0, 0.0], peak_floor=0.01).peaks == 2


@pytest.fixture(scope="module")
def planar_grid(planar_planner):
    return open_loop_grid(planar_planner, DISTANCES, WIDTHS)


@pytest.fixture(scope="module")
def planar_result(planar_grid):
    return measure_human_targets(comanip.presets.planar(), planar_grid, n_samples=2000, seed=0)


def _verdict(result, start):
    return next(v for v in result.verdicts if v.target.startswith(start))


@pytest.mark.slow
def test_planar_preset_reproduces_the_known_failures(planar_result):
    # the shipped preset misses the hit-rate band somewhere and peaks late in most conditions (docs/results/calibration.md)
    for name in ("hit rate at MT, closed form", "hit rate at MT, Monte Carlo"):
        verdict = _verdict(planar_result, name)
        assert not verdict.passed and verdict.low < 0.9 and verdict.failing
    late = _verdict(planar_result, "t_peak/MT")
    assert not late.passed and late.high > 0.5
    assert planar_result.asymmetry_slope > 0 and not _verdict(planar_result, "slope of t_peak/MT").passed
    assert _verdict(planar_result, "plan converged").passed
    assert planar_result.fitts.b > 0 and planar_result.fitts.r2 > 0.9
    assert len(planar_result.rows) == len(DISTANCES) * len(WIDTHS)
    assert len({v.target for v in planar_result.verdicts}) == len(planar_result.verdicts) == 14


@pytest.mark.slow
def test_planar_closed_form_and_monte_carlo_hit_rates_agree(planar_result):
    for row in planar_result.rows:
        p = row.hit_rate_closed_form
        assert row.hit_rate_monte_carlo == pytest.approx(p, abs=4 * np.sqrt(p * (1 - p) / row.samples) + 0.005), row
        assert row.sd_along == pytest.approx(row.sd_along_predicted, rel=0.1)


@pytest.mark.slow
def test_human_section_reports_the_model_beside_the_reference(planar_grid, tmp_path):
    settings = ValidationSettings(human_samples=200)
    faster = comanip.presets.planar().replace(kappa=3e-3, name="planar_kappa_3e-3")
    grid = open_loop_grid(comanip.Planner(faster), DISTANCES, WIDTHS)
    section, results = run_human_section(faster, comanip.presets.planar(), grid, settings, progress=False)
    assert [m["model"] for m in section["models"]] == ["planar_kappa_3e-3", "planar"]
    figure = draw_human_targets_figure(results, tmp_path)
    assert figure == tmp_path / HUMAN_FIGURE and figure.stat().st_size > 0
    json.dumps(_plain(section), allow_nan=False)
    markdown = "\n".join(human_targets_markdown(section))
    assert "planar_kappa_3e-3: verdict" in markdown and "planar: verdict" in markdown and "### planar: per condition" in markdown
    same, _ = run_human_section(comanip.presets.planar(), comanip.presets.planar(), planar_grid, settings, progress=False)
    assert [m["model"] for m in same["models"]] == ["planar"]


def test_validate_rejects_a_bad_targets_reference_before_any_work(tmp_path, capsys):
    assert main(["validate", "--quick", "--no-franka", "--targets-reference", "nope.yaml", "--out", str(tmp_path / "v")]) == 2
    assert "preset" in capsys.readouterr().err
    with pytest.raises(ValueError, match="point-mass"):
        run_validation(comanip.presets.planar(), tmp_path / "w", ValidationSettings(human_reference="franka", franka=False))
    assert not (tmp_path / "v").exists() and not (tmp_path / "w").exists()
