"""The Franka section of ``comanip validate`` (paper Section V-B): ``--preset franka --quick`` runs it alone,
and its numbers have the properties a reader relies on, checked against the plans' own CSV files and the
URDF's limits. The Panda's compiled terms are cached on disk; a first build takes about a minute."""

import csv
import json

import numpy as np
import pytest

import comanip
from comanip.analysis import arm_reaches
from comanip.analysis.speed_profile import SETTLING_FRACTION
from comanip.cli.main import main
from comanip.planning.path_limits import LIMIT_TOLERANCE
from comanip.validation import ValidationSettings, run_validation
from comanip.plots.validation_figures import ARM_FIGURES
from comanip.validation.run_settings import FRANKA_GOAL_OFFSETS

pytestmark = pytest.mark.slow  # the Panda: compiled terms, minutes on a first run


@pytest.fixture(scope="module")
def franka_run(tmp_path_factory):
    """``comanip validate --preset franka --quick``: the output folder and its report.json."""
    out = tmp_path_factory.mktemp("validate_franka")
    assert main(["validate", "--preset", "franka", "--quick", "--out", str(out)]) == 0
    return out, json.loads((out / "report.json").read_text())


@pytest.fixture(scope="module")
def panda():
    return comanip.presets.franka().body


def _plan_rows(out, k) -> dict[str, np.ndarray]:
    """Columns of franka_plans/goal_k.csv; the torque columns have one entry fewer (no command at step H)."""
    with open(out / "franka_plans" / f"goal_{k}.csv") as f:
        rows = list(csv.DictReader(f))
    return {key: np.array([float(r[key]) for r in rows if r[key] != ""]) for key in rows[0]}


def test_an_arm_preset_runs_the_franka_section_alone(franka_run):
    out, report = franka_run
    assert "franka" in report and "fitts_grid" not in report and "calibration" not in report
    assert report["figures"] == list(ARM_FIGURES)
    for name in ["report.md", "franka_reaches.csv", *ARM_FIGURES, *report["franka"]["files"]]:
        assert (out / name).stat().st_size > 0, name
    rows = report["franka"]["reaches"]
    assert [r["offset_m"] for r in rows] == [list(o) for o in FRANKA_GOAL_OFFSETS[:3]]
    assert [r["warm_started"] for r in rows] == [False, True, True]
    assert all(r["solve_time_s"] > 0 and r["iterations"] > 0 for r in rows)
    markdown = (out / "report.md").read_text()
    assert "## Franka Emika Panda" in markdown and "## Fitts' law" not in markdown
    assert all(r["goal_label"] in markdown for r in rows)


def test_every_plan_succeeds_and_ends_within_the_goal_width(franka_run):
    out, report = franka_run
    for k, r in enumerate(report["franka"]["reaches"]):
        assert r["success"], (r["goal_label"], r["status"], r["message"])
        plan = _plan_rows(out, k)
        final = np.array([plan[f"x_{a}_m"][-1] for a in "xyz"])
        assert np.linalg.norm(final - r["goal_m"]) < r["width_m"]
        assert np.linalg.norm(final - r["goal_m"]) == pytest.approx(r["final_error_m"], rel=1e-6)
    summary = report["franka"]["summary"]
    assert summary["successes"] == summary["within_width"] == summary["reaches"] == 3


def test_limits_hold_on_every_step_and_the_usage_is_what_the_plans_show(franka_run, panda):
    out, report = franka_run
    for k, r in enumerate(report["franka"]["reaches"]):
        plan = _plan_rows(out, k)
        q = np.column_stack([plan[f"q{j}"] for j in range(7)])[1:]
        qdot = np.column_stack([plan[f"qdot{j}"] for j in range(7)])[1:]
        tau = np.column_stack([plan[f"tau{j}"] for j in range(7)])
        assert np.all(q <= panda.q_max + LIMIT_TOLERANCE) and np.all(q >= panda.q_min - LIMIT_TOLERANCE)
        assert np.all(np.abs(qdot) <= panda.qdot_max + LIMIT_TOLERANCE)
        assert np.all(np.abs(tau) <= panda.tau_max + 1e-9)
        assert r["within_limits"]
        np.testing.assert_allclose(r["velocity_usage_per_joint"], np.abs(qdot).max(axis=0) / panda.qdot_max, rtol=1e-9)
        np.testing.assert_allclose(r["torque_usage_per_joint"], np.abs(tau).max(axis=0) / panda.tau_max, rtol=1e-9)
        nearest_limit = np.minimum(panda.q_max - q, q - panda.q_min).min(axis=0)  # rad, per joint
        half_range = (panda.q_max - panda.q_min) / 2
        np.testing.assert_allclose(r["position_usage_per_joint"], 1 - nearest_limit / half_range, rtol=1e-9)
        after_mt = plan["t_s"][1:] > r["movement_time"]
        assert r["velocity_usage_after_mt"] == pytest.approx(np.max(np.abs(qdot[after_mt]) / panda.qdot_max), rel=1e-9)
    summary = report["franka"]["summary"]
    assert summary["within_limits"] == 3
    assert 0 < summary["torque_usage_max"] < 1 + 1e-9 and summary["velocity_usage_max"] < 1 + 1e-6


def test_hand_speed_rises_from_rest_to_one_peak_and_settles(franka_run):
    out, report = franka_run
    for k, r in enumerate(report["franka"]["reaches"]):
        plan = _plan_rows(out, k)
        t = plan["t_s"]
        speed = np.linalg.norm(np.column_stack([plan[f"v_{a}_m_per_s"] for a in "xyz"]), axis=1)
        peak = speed.max()
        assert speed[0] == pytest.approx(0, abs=1e-12), "reaches start at rest"
        assert r["peak_speed"] == pytest.approx(peak, rel=0.05) and r["settled"]
        assert 0 < r["t_peak"] < r["movement_time"] < t[-1]
        # single-peaked: one local maximum above a fifth of the peak, and after MT the hand stays slow
        interior = speed[1:-1]
        maxima = (interior > speed[:-2]) & (interior >= speed[2:]) & (interior > 0.2 * peak)
        assert maxima.sum() == 1, speed.round(3)
        assert speed[t > r["movement_time"]].max() < 0.2 * peak, speed.round(3)
        assert speed[np.searchsorted(t, r["movement_time"])] < 2 * SETTLING_FRACTION * peak


def test_a_point_mass_run_plans_the_franka_section_with_the_franka_preset(tmp_path, monkeypatch, franka_run):
    """The wiring of the default run, without its cost: the point-mass analyses and the arm's planning are
    replaced by stand-ins; the section's report is the one the module's real run produced."""
    import comanip.validation.run as run_module

    arms = []
    monkeypatch.setattr(run_module, "_point_mass_sections", lambda *args: ({}, None, []))  # (sections, figure data, grid)
    monkeypatch.setattr(run_module, "run_arm_section",
                        lambda arm, out, settings, progress: (arms.append(arm) or franka_run[1]["franka"], None))
    report = run_validation(comanip.presets.planar(), tmp_path, ValidationSettings.quick_run(human_targets=False), progress=False)
    assert [arm.name for arm in arms] == ["franka"] and arms[0].body.name == "panda"
    assert report["model"]["name"] == "planar" and "franka" in report
    assert "Arm model `franka`" in (tmp_path / "report.md").read_text()


def test_no_franka_with_an_arm_preset_is_refused_before_any_work(tmp_path, capsys):
    assert main(["validate", "--preset", "franka", "--no-franka", "--out", str(tmp_path / "v")]) == 2
    assert "--no-franka" in capsys.readouterr().err
    assert not (tmp_path / "v").exists()


@pytest.mark.parametrize("changes, word", [({"franka_goal_offsets": ()}, "franka_goal_offsets"),
                                           ({"franka_goal_offsets": ((0.1, 0.0),)}, "franka_goal_offsets"),
                                           ({"franka_width": 0.0}, "franka_width"),
                                           ({"franka_max_wall_time": float("nan")}, "franka_max_wall_time"),
                                           ({"franka": "yes"}, "franka")])
def test_bad_franka_settings_name_the_setting(changes, word):
    with pytest.raises(ValueError, match=word):
        ValidationSettings(**changes)


def test_arm_reaches_needs_an_arm(planar_planner):
    with pytest.raises(ValueError, match="joint limits"):
        arm_reaches(planar_planner, [[0.1, 0.0]])
