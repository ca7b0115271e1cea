"""comanip.fitting.fit_timing and the timing it fits: movement timing of speed profiles, recorded trials timed as
the model's reaches, the parameters recovered from closed-loop reaches the model itself executed, and the `arm`
preset (what the fit gives on the recorded arm reaches in ../shared, where present) against those reaches."""

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import comanip
from comanip.analysis import movement_timing, speed_metrics
from comanip.analysis.fitts import fit_fitts
from comanip.cli.main import main
from comanip.execution import execute_receding_horizon
from comanip.fitting import Trial
from comanip.fitting.closed_loop_timing import closed_loop_timing, mean_reach_timing, recorded_velocities
from comanip.fitting.timing_fit import fit_timing
from comanip.recordings import load_tathum

TRUE_KAPPA = 2e-2
START_KAPPA = 8e-3
GOALS = [((0.3, 0.0), 0.02), ((0.15, 0.15), 0.01), ((0.2, -0.1), 0.03)]
TRIALS_PER_GOAL = 12
ARMS = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"


def minimum_jerk_speed(t: np.ndarray, onset: float, duration: float, distance: float) -> np.ndarray:
    """Speed (m/s) of a minimum-jerk reach of ``distance`` m lasting ``duration`` s from ``onset``, at rest around it."""
    tau = np.clip((t - onset) / duration, 0.0, 1.0)
    return distance / duration * 30 * tau**2 * (1 - tau) ** 2


@settings(max_examples=40, deadline=None)
@given(onset=st.floats(0.0, 0.3), duration=st.floats(0.2, 1.0), distance=st.floats(0.01, 0.8))
def test_timing_follows_the_profile_not_its_start_or_size(onset, duration, distance):
    t = np.arange(0.0, onset + duration + 0.3, 0.004)
    timing = movement_timing(t, minimum_jerk_speed(t, onset, duration, distance))
    # minimum jerk, speed / peak = 16 τ²(1−τ)²: at 2.5 % of its peak at τ = 0.0412, at 5 % at τ = 1 − 0.0595
    tau_on, tau_end = 0.0412, 0.9405
    assert timing.onset == pytest.approx(onset + tau_on * duration, abs=0.004)
    assert timing.movement_time == pytest.approx((tau_end - tau_on) * duration, abs=0.005)
    assert timing.peak_fraction == pytest.approx((0.5 - tau_on) / (tau_end - tau_on), abs=0.02)
    assert timing.peak_speed == pytest.approx(1.875 * distance / duration, rel=0.01)


def test_a_corrective_sub_movement_is_inside_the_movement():
    t = np.arange(0.0, 1.5, 0.004)
    primary, correction = minimum_jerk_speed(t, 0.1, 0.4, 0.2), minimum_jerk_speed(t, 0.7, 0.3, 0.02)
    alone, corrected = movement_timing(t, primary), movement_timing(t, primary + correction)
    first_fall = speed_metrics(t, primary + correction)
    assert 0.7 + 0.15 < corrected.onset + corrected.movement_time < 1.0     # ends in the correction's deceleration
    assert first_fall.movement_time < 0.1 + alone.movement_time + 0.05   # the first fall below 5 % does not
    assert corrected.onset == pytest.approx(alone.onset)


def test_a_profile_still_moving_at_its_end_has_no_movement_time():
    t = np.arange(0.0, 0.4, 0.004)
    timing = movement_timing(t, minimum_jerk_speed(t, 0.05, 0.5, 0.2))
    assert np.isnan(timing.movement_time) and np.isnan(timing.peak_fraction)


def test_a_recorded_trial_is_timed_as_its_speed():
    """Positions of a minimum-jerk reach sampled at 250 Hz, cut at the sample after their end as motion-capture trials
    are: their timing from positions is the speed's."""
    step, onset, duration, distance = 0.004, 0.02, 0.45, 0.25
    t = np.arange(0.0, 1.0, step)
    tau = np.clip((t - onset) / duration, 0.0, 1.0)
    direction = np.array([0.6, 0.8, 0.0])
    position = np.outer(distance * (10 * tau**3 - 15 * tau**4 + 6 * tau**5), direction)
    exact = movement_timing(t, minimum_jerk_speed(t, onset, duration, distance))
    cut = int(np.searchsorted(t, exact.onset + exact.movement_time)) + 1
    trial = Trial("cut", t[:cut], position[:cut], position[-1], 0.01)
    velocity = recorded_velocities([trial], step)[0]
    assert len(velocity) >= cut + 1 and np.all(velocity[cut:] == 0)    # at rest after its last sample
    timing = mean_reach_timing(step, velocity)
    assert timing.movement_time == pytest.approx(exact.movement_time, abs=2 * step)
    assert timing.peak_fraction == pytest.approx(exact.peak_fraction, abs=0.01)


@pytest.fixture(scope="module")
def synthetic_trials():
    """Closed-loop reaches the planar preset at kappa = TRUE_KAPPA executed (seeds apart from the fit's), their hand
    positions at the model's steps, each cut after it comes to rest."""
    model = comanip.presets.planar().replace(kappa=TRUE_KAPPA)
    planner = comanip.Planner(model)
    trials = []
    for g, (goal, width) in enumerate(GOALS):
        for k in range(TRIALS_PER_GOAL):
            run = execute_receding_horizon(planner, np.zeros(4), goal, width, steps=2 * model.H,
                                           rng=np.random.default_rng([1000 + g, k]))
            trials.append(Trial(f"g{g}-{k}", run.t, run.ee, np.array(goal), width))
    return trials


@pytest.fixture(scope="module")
def kappa_timing_fit(synthetic_trials):
    return fit_timing(comanip.presets.planar().replace(kappa=START_KAPPA), synthetic_trials, ["kappa"], executions=6,
                      progress=False)


@pytest.mark.slow
def test_timing_fit_recovers_kappa_from_the_models_closed_loop_reaches(kappa_timing_fit):
    fit = kappa_timing_fit
    kappa, se = fit.values["kappa"], fit.std_errors["kappa"]
    assert fit.success and fit.status == "converged", fit.message
    assert kappa == pytest.approx(TRUE_KAPPA, rel=0.2)
    assert abs(kappa - TRUE_KAPPA) < 3 * se
    assert fit.objective_kind.startswith("chi²")
    # the fitted model's mean reach takes the recorded one's time in every condition, and peaks as early
    for row in fit.conditions:
        assert row["mt_predicted_s"] == pytest.approx(row["mt_recorded_s"], rel=0.08)
        assert row["peak_fraction_predicted"] == pytest.approx(row["peak_fraction_recorded"], abs=0.05)


@pytest.mark.slow
def test_timing_fit_from_the_cli_writes_the_fitted_model(synthetic_trials, tmp_path):
    lines = ["trial,t,x,y,goal_x,goal_y,width"]
    for trial in synthetic_trials[::3]:
        lines += [f"{trial.name},{t!r},{x!r},{y!r},{trial.goal[0]},{trial.goal[1]},{trial.width}"
                  for t, (x, y) in zip(trial.t.tolist(), trial.position.tolist())]
    csv = tmp_path / "reaches.csv"
    csv.write_text("\n".join(lines) + "\n")
    out = tmp_path / "fit"
    code = main(["fit", "--recordings", str(csv), "--match", "timing", "--preset", "planar", "--parameters", "kappa",
                 "--executions", "3", "--max-evaluations", "12", "--no-progress", "--out", str(out)])
    written = json.loads((out / "fit.json").read_text())
    assert code in (0, 1) and written["objective_kind"].startswith("chi²")
    assert set(written["values"]) == {"kappa"} and written["values"]["kappa"] > START_KAPPA
    assert comanip.presets.load(out / "model.yaml").kappa == pytest.approx(written["values"]["kappa"])


def test_timing_fit_refuses_bad_input_before_executing(synthetic_trials):
    model = comanip.presets.planar()
    with pytest.raises(ValueError, match="sigma_obs"):
        fit_timing(model, synthetic_trials, ["kappa", "sigma_obs"])
    with pytest.raises(ValueError, match="executions"):
        fit_timing(model, synthetic_trials, ["kappa"], executions=0)
    with pytest.raises(ValueError, match="seed"):
        fit_timing(model, synthetic_trials, ["kappa"], seed=-1)
    with pytest.raises(ValueError, match="at least 3 trials per condition"):
        fit_timing(model, synthetic_trials[:2], ["kappa"])
    with pytest.raises(ValueError, match="hand moves in 3-D"):
        fit_timing(comanip.presets.cartesian(), synthetic_trials, ["kappa"])


@pytest.mark.slow
@pytest.mark.skipif(not ARMS.is_dir(), reason="the recorded arm reaches live in ../shared, beside the repository")
def test_the_arm_preset_takes_the_recorded_arms_time_peaks_as_early_and_keeps_fitts_law():
    """The preset's mean closed-loop reach (96 executions: over fewer its peak scatters by a few hundredths) over the
    recordings' median distance takes their median movement time (within 10 %) and peaks inside their interquartile
    range of t_peak/MT; its plans keep Fitts' law on the validation grid (80–160 ms/bit, R² ≥ 0.95)."""
    recordings = [trial.recording() for trial in load_tathum(ARMS)]
    peak_fractions = [(r.t[int(np.argmax(np.linalg.norm(r.velocity, axis=1)))] - r.onset) / r.movement_time
                      for r in recordings]
    low, high = np.percentile(peak_fractions, [25, 75])
    model = comanip.presets.arm()
    planner = comanip.Planner(model)
    start = np.zeros(model.state_size)
    distance = float(np.median([r.distance for r in recordings]))
    timing = closed_loop_timing(planner, start, np.array([distance, 0.0, 0.0]), model.width, executions=96, seed=0)
    assert timing.movement_time == pytest.approx(np.median([r.movement_time for r in recordings]), rel=0.1)
    assert low <= timing.peak_fraction <= high, (timing.peak_fraction, low, high)
    grid = [(D, w) for D in (0.15, 0.3, 0.45) for w in (0.005, 0.01, 0.02, 0.04)]
    times = [speed_metrics(plan.t, plan.ee_speed).movement_time
             for plan in (planner.solve(start, [D, 0.0, 0.0], w) for D, w in grid)]
    fitts = fit_fitts(*map(np.array, zip(*grid)), np.array(times))
    assert 0.08 <= fitts.b <= 0.16 and fitts.r2 >= 0.95, fitts
