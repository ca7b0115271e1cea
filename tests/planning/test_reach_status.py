"""Plans say whether they reach: a converged plan that ends farther than w from the goal is 'goal_not_reached'."""

import json

import numpy as np
import pytest

import comanip
from comanip.cli.main import main
from comanip.planning.plan import with_reach_check


def test_a_far_goal_is_not_reached(planar_planner):
    plan = planar_planner.solve(np.zeros(4), [1000.0, 0.0], 0.01)
    assert plan.status == "goal_not_reached" and not plan.success, plan.message
    assert plan.converged and plan.extras["solver_status"] in ("solved", "solved_acceptable")
    assert plan.final_error > 999 and not plan.reaches_goal and "beyond the goal width" in plan.message


def test_a_near_goal_is_reached_and_solved(planar_planner):
    plan = planar_planner.solve(np.zeros(4), [0.3, 0.0], 0.02)
    assert plan.status in ("solved", "solved_acceptable") and plan.success and plan.reaches_goal and plan.converged


@pytest.mark.parametrize("preset", ["cartesian", "human"])
def test_every_point_mass_body_checks_the_reach(preset):
    model = getattr(comanip.presets, preset)().replace(H=20)
    plan = comanip.Planner(model).solve(np.zeros(2 * model.n), 500.0 * np.eye(model.d)[0], model.width, max_wall_time=20)
    assert plan.status == "goal_not_reached" and not plan.success


def test_the_check_leaves_unconverged_and_reaching_plans_alone(planar_planner):
    plan = planar_planner.solve(np.zeros(4), [0.3, 0.0], 0.02)
    assert with_reach_check(plan) is plan
    for status in ("max_iterations", "max_wall_time", "failed", "unreachable"):
        stalled = with_reach_check(comanip.Plan(**{**plan.__dict__, "status": status, "success": False,
                                                     "goal": np.array([5.0, 0.0])}))
        assert stalled.status == status and not stalled.converged


def test_cli_plan_reports_the_goal_not_reached(tmp_path, capsys):
    assert main(["plan", "--goal", "1000,0", "--out", str(tmp_path), "--verbose"]) == 1
    summary = json.loads(capsys.readouterr().out)
    assert (summary["success"], summary["status"], summary["reaches_goal"]) == (False, "goal_not_reached", False)


@pytest.mark.parametrize("width", [5.3e153, 1e-300, 1e4])
def test_widths_outside_floating_point_range_are_refused(planar_planner, width):
    """A goal width whose reward peak under- or overflows (fuzz: 5.3e153 m divided by zero) is refused up front."""
    with pytest.raises(ValueError, match="between 1e-06 and 1000 m"):
        planar_planner.solve(np.zeros(4), [0.2, 0.0], width)
    with pytest.raises(ValueError, match="between 1e-06 and 1000 m"):
        comanip.presets.planar().replace(width=width)
