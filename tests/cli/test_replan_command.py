"""``comanip replan``: the closed loop at a controller's rate beside the converged loop, its files, and its errors."""

import csv
import json

import numpy as np
import pytest

from comanip.cli.main import main
from tests.cli.test_cli_errors import assert_one_line_error, run_cli


def test_a_planar_loop_with_a_goal_jump_writes_its_cycles_and_ends_where_the_converged_loop_ends(tmp_path, capsys):
    """Without motor noise at 100 Hz over 0.9 s with the goal jumping at 0.3 s: one CSV row per cycle with its
    iterations and hand position; the hand ends within the goal's width of the jumped goal and of where the loop
    converged every cycle ends; the summary says what the rows say."""
    out = tmp_path / "replan"
    code = main(["replan", "--goal", "0.3,0.1", "--no-noise", "--duration", "0.9", "--jump-at", "0.3", "--jump-to",
                 "0.3,0.15", "--out", str(out), "--png"])
    assert code == 0, capsys.readouterr()
    summary = json.loads((out / "replan.json").read_text())
    with open(out / "replan.csv", newline="") as file:
        rows = list(csv.DictReader(file))
    assert len(rows) == summary["cycles"] == 90
    assert all(int(row["iterations"]) == 1 for row in rows[1:])            # one Newton iteration every cycle
    cycles = np.array([float(row["cycle_ms"]) for row in rows[1:]])
    assert summary["cycle_ms"]["median"] == pytest.approx(np.median(cycles))
    assert summary["goal"] == [0.3, 0.15]
    assert summary["final_error_m"] <= summary["width"] and summary["hand_end_from_converged_m"] <= summary["width"]
    assert abs(summary["executed_cost_vs_converged_of_J_best"]) < 0.01
    assert (out / "replan.png").stat().st_size > 0


@pytest.mark.parametrize("argv, fragments", [
    (["--rate", "0"], ["rate must be"]),
    (["--iterations", "0"], ["iterations must be an integer ≥ 1"]),
    (["--budget", "-1"], ["budget must be"]),
    (["--jump-at", "0.3"], ["--jump-at and --jump-to go together"]),
    (["--jump-at", "0.3", "--jump-to", "0.3,0.1,0"], ["jump_to must have shape (2,)"]),
    (["--goal", "0.3"], ["goal must have shape (2,)"]),
])
def test_a_mistake_is_one_line_before_any_loop_runs_or_the_folder_is_made(argv, fragments, tmp_path, capsys):
    out = tmp_path / "replan"
    assert_one_line_error(*run_cli(["replan", *argv, "--out", str(out)], capsys), *fragments)
    assert not out.exists()
