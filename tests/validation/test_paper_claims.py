"""The paper's validation claims (Section IV-D) on the planar preset, and the ``comanip validate`` command.

Grid: D ∈ {0.15, 0.3, 0.45} m × w ∈ {0.005, 0.01, 0.02, 0.04} m, open-loop plans from rest.
"""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from comanip.analysis import (
    closed_loop_grid,
    endpoint_dispersion,
    fit_fitts,
    index_of_difficulty,
    open_loop_grid,
)
from comanip.analysis.calibration import TREND_TOLERANCE
from comanip.cli.main import main

DISTANCES = [0.15, 0.3, 0.45]
WIDTHS = [0.005, 0.01, 0.02, 0.04]


@pytest.fixture(scope="module")
def grid(planar_planner):
    return open_loop_grid(planar_planner, DISTANCES, WIDTHS)


@pytest.fixture(scope="module")
def movement_times(grid):
    return np.array([o.metrics.movement_time for o in grid]).reshape(len(DISTANCES), len(WIDTHS))


def test_every_reach_converges_and_finishes(grid):
    assert all(o.success for o in grid)
    assert all(o.metrics.settled for o in grid)
    assert max(o.final_error for o in grid) < 0.005


def test_movement_time_is_linear_in_the_index_of_difficulty(grid, movement_times):
    D, w = np.meshgrid(DISTANCES, WIDTHS, indexing="ij")
    fits = [fit_fitts(D, w, movement_times, form) for form in ("fitts", "shannon")]
    assert all(fit.b > 0 for fit in fits), "movement time must grow with the index of difficulty"
    assert max(fit.r2 for fit in fits) >= 0.9


def test_wider_goals_are_reached_no_slower_and_farther_goals_slower(movement_times):
    assert np.all(np.diff(movement_times, axis=1) <= TREND_TOLERANCE), movement_times
    assert np.all(np.diff(movement_times, axis=0) > 0), movement_times


def test_movement_times_lie_in_the_human_range(movement_times):
    assert np.all((movement_times >= 0.2) & (movement_times <= 1.5)), movement_times


def test_movement_time_depends_on_distance_over_width(grid):
    # SPEC §9: multiplicative noise and a negligible effort make the model nearly scale-invariant, so equal
    # D/w (equal ID) gives equal MT: the reason Fitts' law appears
    by_id = {}
    for o in grid:
        by_id.setdefault(round(float(index_of_difficulty(o.distance, o.width)), 6), []).append(o.metrics.movement_time)
    pairs = [times for times in by_id.values() if len(times) > 1]
    assert len(pairs) >= 3
    for times in pairs:
        assert max(times) == pytest.approx(min(times), rel=0.03)


def test_endpoint_spread_along_and_across_grows_with_width(planar_planner, rng):
    spreads = []
    for width in (0.01, 0.02, 0.04):
        plan = planar_planner.solve(np.zeros(4), [0.45, 0.0], width)
        spreads.append(endpoint_dispersion(planar_planner.model, plan, 1500, rng))
    along = np.array([s.along_std for s in spreads])
    across = np.array([s.across_std for s in spreads])
    # relative standard error of each std is ~1.8 % with 1500 samples; require growth well beyond it
    assert np.all(along[1:] > 1.08 * along[:-1]), along
    assert np.all(across[1:] > 1.08 * across[:-1]), across
    hit_rates = [s.hit_rate for s in spreads]
    assert 0 < hit_rates[0] < 1 and hit_rates[-1] > hit_rates[0], "the model accepts some misses (paper Fig. 4)"


def test_closed_loop_execution_brings_the_peak_earlier_than_the_open_loop_plan(planar_planner, grid):
    # the calibration study's finding at a hard condition: feedback removes much of the late-peak bias
    open_loop = next(o for o in grid if (o.distance, o.width) == (0.3, 0.01))
    executed = closed_loop_grid(planar_planner, [0.3], [0.01], n_trials=4, rng=np.random.default_rng(7))[0]
    assert executed.success and executed.metrics.settled
    assert executed.metrics.asymmetry < open_loop.metrics.asymmetry - 0.05


@pytest.mark.slow
def test_validate_quick_writes_figures_and_a_complete_report(tmp_path, grid):
    out = tmp_path / "validate"
    # the Franka section has its own tests (test_franka_section.py); here the flag must skip it
    assert main(["validate", "--quick", "--no-franka", "--out", str(out)]) == 0
    assert not list(out.glob("franka*"))
    for name in ("report.json", "report.md", "velocity_profiles.png", "fitts.png", "dispersion.png", "phase.png",
                 "calibration.png", "asymmetry_vs_difficulty.png"):
        assert (out / name).stat().st_size > 0, name
    report = json.loads((out / "report.json").read_text())
    assert set(report) >= {"model", "settings", "fitts_grid", "dispersion", "phase", "calibration", "figures"}
    assert "franka" not in report and report["settings"]["franka"] is False
    assert len(report["fitts_grid"]["conditions"]) == len(DISTANCES) * len(WIDTHS)
    assert set(report["fitts_grid"]["fits"]) == {"fitts", "shannon"}
    assert [d["width"] for d in report["dispersion"]["widths"]] == [0.02, 0.04]
    rows = report["calibration"]["configurations"]
    assert {r["mode"] for r in rows} == {"open loop", "closed loop"}
    for key in ("asymmetry_min", "asymmetry_median", "asymmetry_max", "mt_min_s", "mt_max_s", "fitts_r2", "shannon_r2",
                "fitts_slope_s_per_bit", "width_trend", "distance_trend", "fitts_law", "early_peak", "both"):
        assert all(key in r for r in rows), key
    # the default configuration, run in worker processes, reproduces this process's plans condition by condition
    default = next(r for r in rows if r["configuration"] == "W=std iso exp H=30")
    assert [c["movement_time"] for c in default["conditions"]] == pytest.approx([o.metrics.movement_time for o in grid], rel=1e-6)
    markdown = (out / "report.md").read_text()
    assert "## Calibration study" in markdown and "W=cov iso exp H=30" in markdown


@pytest.mark.parametrize("argv, word", [(["--workers", "0"], "workers"), (["--seed", "-1"], "seed")])
def test_validate_rejects_bad_options_before_any_work(tmp_path, capsys, argv, word):
    assert main(["validate", "--quick", "--out", str(tmp_path / "v"), *argv]) == 2
    assert word in capsys.readouterr().err
    assert not (tmp_path / "v").exists()


def test_importing_validation_does_not_load_matplotlib():
    """The settings and the package import without the figure layer (a fresh interpreter: pytest has loaded it)."""
    code = "import sys, comanip.validation; assert 'matplotlib' not in sys.modules; comanip.validation.ValidationSettings()"
    subprocess.run([sys.executable, "-c", code], check=True, env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
