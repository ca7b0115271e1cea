"""The analysis functions against cases whose answers are known independently of them."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.linear_model import LinearRegression
from sklearn.metrics import r2_score

from comanip.analysis import (
    Configuration,
    ReachOutcome,
    endpoint_dispersion,
    fit_fitts,
    index_of_difficulty,
    measure_grid,
    minimum_jerk_asymmetry,
    minimum_jerk_velocity,
    phase_curves,
    speed_metrics,
    study_configurations,
    trend_fraction,
)


def min_jerk_speed(t, distance, duration):
    """Flash–Hogan speed from rest to rest, written out here independently of the package."""
    s = np.clip(t / duration, 0, 1)
    return distance / duration * 30 * s**2 * (1 - s) ** 2


def settling_fraction_by_roots(fraction=0.05):
    """Largest s in (0.5, 1) with 16 s²(1-s)² = fraction: the root of a quartic, found numerically."""
    roots = np.roots([16, -32, 16, 0, -fraction])
    real = roots[np.abs(roots.imag) < 1e-12].real
    return real[(real > 0.5) & (real < 1)].max()


@pytest.mark.parametrize("steps", [15, 25, 200])
def test_minimum_jerk_profile_peaks_at_mid_movement_and_settles_at_the_quartic_root(steps):
    duration, distance = 0.5, 0.3
    t = np.linspace(0, 0.8, int(steps * 0.8 / duration) + 1)
    m = speed_metrics(t, min_jerk_speed(t, distance, duration))
    s_f = settling_fraction_by_roots()
    assert m.t_peak == pytest.approx(duration / 2, abs=0.01 * duration)
    assert m.peak_speed == pytest.approx(1.875 * distance / duration, rel=0.01)
    assert m.movement_time == pytest.approx(s_f * duration, rel=0.01)
    assert m.asymmetry == pytest.approx(0.5 / s_f, rel=0.02)
    assert minimum_jerk_asymmetry() == pytest.approx(0.5 / s_f, rel=1e-12)


def test_movement_time_of_a_piecewise_linear_profile_is_exact():
    # a symmetric triangle (so the peak needs no refinement): 1 m/s at 0.2 s, 0 at 0.4 s; below 5 % of the
    # peak after 0.2 + 0.95·0.2 s, between two samples
    t = np.arange(0, 0.6001, 0.02)
    speed = np.interp(t, [0, 0.2, 0.4, 0.6], [0, 1, 0, 0])
    m = speed_metrics(t, speed)
    assert (m.t_peak, m.peak_speed, m.movement_time) == pytest.approx((0.2, 1.0, 0.39), abs=1e-12)


@given(st.floats(0.15, 0.45))
@settings(max_examples=25, deadline=None)
def test_peak_refinement_beats_the_sample_grid(true_peak):
    t = np.arange(0, 0.8, 0.02)
    speed = np.exp(-0.5 * ((t - true_peak) / 0.08) ** 2)
    m = speed_metrics(t, speed)
    assert abs(m.t_peak - true_peak) < 0.1 * 0.02
    assert abs(m.t_peak - true_peak) <= abs(t[np.argmax(speed)] - true_peak) + 1e-12


def test_a_profile_that_never_slows_down_has_no_movement_time():
    t = np.linspace(0, 1, 11)
    m = speed_metrics(t, np.linspace(0, 1, 11))
    assert not m.settled and np.isnan(m.movement_time) and np.isnan(m.asymmetry)


@pytest.mark.parametrize("t, speed, word", [(np.arange(3), np.ones(4), "t and speed"),
                                            (np.array([0, 1, 3.0]), np.ones(3), "uniformly"),
                                            (np.arange(4.0), np.array([0, 1, np.nan, 0]), "finite")])
def test_bad_speed_profiles_are_rejected(t, speed, word):
    with pytest.raises(ValueError, match=word):
        speed_metrics(t, speed)


def test_minimum_jerk_baseline_has_the_requested_movement_time_and_covers_the_distance():
    t = np.linspace(0, 1.0, 2001)
    velocity = minimum_jerk_velocity([0.0, 0.0], [0.3, 0.4], 0.37, t)
    m = speed_metrics(t, np.linalg.norm(velocity, axis=1))
    assert m.movement_time == pytest.approx(0.37, rel=1e-3)
    np.testing.assert_allclose(np.trapezoid(velocity, t, axis=0), [0.3, 0.4], rtol=1e-4)


def test_index_of_difficulty_known_values():
    assert index_of_difficulty(0.16, 0.02, "fitts") == pytest.approx(4.0)
    assert index_of_difficulty(0.3, 0.1, "shannon") == pytest.approx(2.0)
    with pytest.raises(ValueError, match="width"):
        index_of_difficulty(0.3, 0.0)
    with pytest.raises(ValueError, match="form"):
        index_of_difficulty(0.3, 0.01, "welford")


@pytest.mark.parametrize("form", ["fitts", "shannon"])
def test_fit_of_exact_linear_data_recovers_the_line_with_r2_one(form):
    D, w = np.meshgrid([0.15, 0.3, 0.45], [0.005, 0.01, 0.02, 0.04])
    mt = 0.11 + 0.048 * index_of_difficulty(D, w, form)
    fit = fit_fitts(D, w, mt, form)
    assert (fit.a, fit.b, fit.r2, fit.n_points) == pytest.approx((0.11, 0.048, 1.0, 12), rel=1e-10)
    np.testing.assert_allclose(fit.predict(D, w), mt, rtol=1e-10)


def test_fit_of_noisy_data_matches_scikit_learn(rng):
    D, w = rng.uniform(0.1, 0.5, 20), rng.uniform(0.005, 0.05, 20)
    ids = index_of_difficulty(D, w, "shannon")
    mt = 0.1 + 0.05 * ids + rng.normal(scale=0.02, size=20)
    mt[3] = np.nan  # an unfinished reach is left out
    keep = np.isfinite(mt)
    reference = LinearRegression().fit(ids[keep, None], mt[keep])
    fit = fit_fitts(D, w, mt, "shannon")
    assert fit.n_points == 19
    assert (fit.a, fit.b) == pytest.approx((reference.intercept_, reference.coef_[0]), rel=1e-9)
    assert fit.r2 == pytest.approx(r2_score(mt[keep], reference.predict(ids[keep, None])), rel=1e-9)
    assert fit.r2 < 0.99


def test_trend_fraction_counts_pairs():
    assert trend_fraction([[3, 2, 1], [1, 2, 2.0005]], increasing=True, tolerance=1e-3) == pytest.approx(0.5)
    assert trend_fraction([3, 2, 2.0005, 1], increasing=False, tolerance=1e-3) == 1.0
    assert trend_fraction([3, np.nan, 1], increasing=False) == 0.0


def synthetic_outcome(distance, width, movement_time, asymmetry_stretch=1.0):
    """A reach whose speed is a minimum-jerk bell, optionally with its rising part compressed in time."""
    t = np.linspace(0, 1.5, 751)
    duration = movement_time / 0.9406
    if asymmetry_stretch == 1.0:
        speed = min_jerk_speed(t, distance, duration)
    else:  # time warp: peak moved from duration/2 to asymmetry_stretch·duration/2, shape kept
        peak = asymmetry_stretch * duration / 2
        warped = np.where(t < peak, t * (duration / 2) / peak, duration / 2 + (t - peak) * (duration / 2) / (duration - peak))
        speed = min_jerk_speed(warped, distance, duration)
    velocity = np.stack([speed, np.zeros_like(speed)], axis=1)
    return ReachOutcome(distance, width, t, velocity, speed_metrics(t, speed), True, 0.0)


def test_calibration_verdicts_follow_the_criteria():
    D, w = [0.15, 0.3, 0.45], [0.005, 0.01, 0.02, 0.04]
    law = lambda d, x: 0.1 + 0.05 * float(index_of_difficulty(d, x))  # noqa: E731
    symmetric = measure_grid([synthetic_outcome(d, x, law(d, x)) for d in D for x in w], Configuration("bell"))
    row = symmetric.summary()
    assert row["fitts_law"] and not row["early_peak"] and not row["both"]
    assert row["fitts_r2"] > 0.999 and row["fitts_slope_s_per_bit"] == pytest.approx(0.05, rel=0.01)
    assert row["asymmetry_median"] == pytest.approx(minimum_jerk_asymmetry(), abs=0.01)

    early = measure_grid([synthetic_outcome(d, x, law(d, x), 0.7) for d in D for x in w], Configuration("early"))
    assert early.summary()["both"]

    flat = measure_grid([synthetic_outcome(d, x, 0.3, 0.7) for d in D for x in w], Configuration("flat"))
    row = flat.summary()
    assert row["early_peak"] and not row["fitts_law"]


def test_study_configurations_are_valid_distinct_models(planar_planner):
    base = planar_planner.model
    for quick in (False, True):
        configurations = study_configurations(quick)
        assert len({c.name for c in configurations}) == len(configurations)
        models = [c.model(base).config() | {"closed_loop": c.closed_loop, "name": ""} for c in configurations]
        assert len({repr(m) for m in models}) == len(models)


def test_dispersion_monte_carlo_matches_the_plans_closed_form_covariance(planar_planner, rng):
    plan = planar_planner.solve(np.zeros(4), [0.45, 0.0], 0.02)
    result = endpoint_dispersion(planar_planner.model, plan, 4000, rng)
    assert result.time == plan.t[result.step] and result.time >= speed_metrics(plan.t, plan.ee_speed).movement_time
    # std of a std estimate from 4000 samples is ~1.1 %
    assert result.along_std == pytest.approx(result.predicted_along_std, rel=0.05)
    assert result.across_std == pytest.approx(result.predicted_across_std, rel=0.05)
    assert result.across_fit_std == pytest.approx(result.across_std, rel=0.01)
    assert abs(result.across_fit_mean) < 4 * result.across_std / np.sqrt(4000)
    np.testing.assert_allclose(result.paths.mean(axis=0), plan.ee_mean, atol=5 * result.across_std / np.sqrt(4000) + 1e-9)
    hits = np.linalg.norm(result.paths[:, result.step] - plan.goal, axis=1) <= 0.02
    assert result.hit_rate == pytest.approx(hits.mean())


def test_phase_curves_start_with_the_requested_velocity_and_end_on_the_goal(planar_planner):
    curves = phase_curves(planar_planner, [0.2], [-0.3, 0.0, 0.5], 0.02)
    for curve in curves:
        assert curve.success
        assert curve.position[0] == 0 and curve.velocity[0] == pytest.approx(curve.initial_velocity)
        assert curve.position[-1] == pytest.approx(0.2, abs=0.01)
        assert abs(curve.velocity[-1]) < 0.05 * np.abs(curve.velocity).max()
