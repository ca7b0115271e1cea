"""The arm's reach library: its grid covers the goals it is for, it ships for the Panda presets and only for
them, and a cold solve from the ready pose that starts from it reaches the plan of the full search."""

import numpy as np
import pytest

import comanip
from comanip.cli.main import main as comanip_main
from comanip.planning.starts.arm_reach_library import (GRID_SPACING, SHELL, ArmReachLibrary, build_library, bundled_library,
                                                grid_goals)
from comanip.planning.starts.initial_guess import minimum_jerk, minimum_jerk_torques
from comanip.planning.solver_options import SolverOptions

RELATIVE = 1e-6
"""Objectives of a cold solve from the library and of the full search agree to this (relative)."""


def test_every_goal_in_the_shell_has_an_entry_within_half_a_grid_diagonal():
    hand = np.array([0.3, 0.0, 0.5])
    goals = grid_goals(hand)
    distances = np.linalg.norm(goals - hand, axis=1)
    assert np.all((distances >= SHELL[0]) & (distances <= SHELL[1])) and np.all(np.diff(distances) >= -1e-12)
    rng = np.random.default_rng(0)
    directions = rng.normal(size=(2000, 3))
    queries = hand + rng.uniform(0.15, 0.3, (2000, 1)) * directions / np.linalg.norm(directions, axis=1, keepdims=True)
    nearest = np.min(np.linalg.norm(queries[:, None] - goals[None], axis=2), axis=1)
    assert np.max(nearest) <= np.sqrt(3) / 2 * GRID_SPACING + 1e-12


def test_franka_rest_ships_a_library_of_its_own():
    model = comanip.presets.load("franka_rest")
    library = bundled_library(model)
    assert library is not None and library.is_for(model) and library.serves(np.r_[model.body.home_position, np.zeros(7)])
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    assert len(library.goals) >= 0.9 * len(grid_goals(hand))  # a few goals may be out of the arm's reach
    assert library.torques.shape[1:] == (model.H, model.n) and np.all(np.isfinite(library.torques))
    assert bundled_library(model.replace(kappa=2 * model.kappa)) is None  # another model: not its library
    assert not library.serves(np.r_[model.body.home_position + 0.01, np.zeros(7)])


def test_models_without_a_library_file_get_none():
    assert bundled_library(comanip.presets.planar()) is None
    assert bundled_library(comanip.presets.franka()) is None  # the paper's preset: every guess, as before


def test_a_saved_library_loads_back(tmp_path):
    rng = np.random.default_rng(1)
    library = ArmReachLibrary("key", np.zeros(14), 0.05, rng.normal(size=(4, 3)), rng.normal(size=(4, 50, 7)))
    loaded = ArmReachLibrary.load(library.save(tmp_path / "lib.npz"))
    assert loaded.model_key == "key" and loaded.width == 0.05
    np.testing.assert_array_equal(loaded.goals, library.goals)
    np.testing.assert_allclose(loaded.torques, library.torques, rtol=1e-6)  # stored as float32
    nearest_goal, _ = loaded.nearest(library.goals[2] + 1e-3, count=1)[0]
    np.testing.assert_array_equal(nearest_goal, library.goals[2])


def test_malformed_library_is_refused():
    with pytest.raises(ValueError, match="one row per entry"):
        ArmReachLibrary("key", np.zeros(14), 0.05, np.zeros((4, 3)), np.zeros((3, 50, 7)))


def test_minimum_jerk_torques_of_an_arm_are_its_inverse_dynamics_step_by_step():
    model = comanip.presets.franka()
    body = model.body
    start = np.r_[body.home_position, np.linspace(-0.2, 0.2, 7)]
    goal_q = body.home_position + 0.3
    torques = minimum_jerk_torques(body, model.h, model.H, start, goal_q, 0.8)
    q, qdot, qddot = minimum_jerk(start[:7], start[7:], goal_q, 0.8, model.h * np.arange(model.H))
    one_by_one = np.array([body.inverse_dynamics(q[i], qdot[i], qddot[i]) for i in range(model.H)])
    np.testing.assert_allclose(torques, body.command_for_force(one_by_one, model.h), rtol=0, atol=1e-10)


@pytest.mark.parametrize("preset", ["planar", "franka_rest"])
def test_a_braked_plan_from_a_moving_start_follows_the_plan_from_rest(preset):
    """braked_torques: from a start moving at v the braked torques give nearly the mean path of the plan from
    rest once the braking has ended (the move is continuous-time, the step forward Euler; for the Panda also
    first order in the nonlinearity): the end state is ten times closer to the plan's than without braking."""
    from comanip.belief.propagation import propagate_belief
    from comanip.planning.starts.initial_guess import braked_torques

    model = comanip.presets.load(preset)
    body, n = model.body, model.n
    rest = np.r_[body.home_position, np.zeros(n)]
    torque = minimum_jerk_torques(body, model.h, model.H, rest, body.home_position + 0.1, 0.5 * model.duration)
    plan = propagate_belief(body, model.h, model.kappa, rest, torque, model.noise)[0]
    moving = rest + np.r_[np.zeros(n), np.linspace(-0.3, 0.3, n)]
    braked = [propagate_belief(body, model.h, model.kappa, moving, t, model.noise)[0]
              for t in braked_torques(body, model.h, model.H, torque, moving[n:], [0.3, 0.6], plan)]
    unbraked = propagate_belief(body, model.h, model.kappa, moving, torque, model.noise)[0]
    for path in braked:
        assert np.linalg.norm(path[-1] - plan[-1]) < 0.1 * np.linalg.norm(unbraked[-1] - plan[-1])


def test_library_cli_refuses_a_point_mass(capsys):
    assert comanip_main(["library", "--preset", "planar"]) == 2
    assert "point mass" in capsys.readouterr().err


@pytest.mark.slow
def test_cold_solves_from_a_small_library_reach_the_full_searchs_plans(tmp_path):
    """A library of six goals built here: cold solves to goals near them start from their plans and end on the
    full search's plans in fewer iterations; the library of another model is refused."""
    model = comanip.presets.load("franka_rest")
    full = comanip.Planner(model, SolverOptions(cold_search="all"))
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    entries = hand + 0.2 * np.vstack([np.eye(3), -np.eye(3)])
    library = build_library(model, lambda s, g, warm: full.solve(s, g, warm_start=warm), entries)
    path = library.save(tmp_path / "library.npz")
    ranked = comanip.Planner(model, SolverOptions(arm_library=str(path)))
    for goal in (hand + [0.05, 0.18, 0.03], hand + [-0.04, 0.02, -0.21]):
        fast, reference = ranked.solve(start, goal), full.solve(start, goal)
        assert fast.success and reference.success
        assert (fast.objective - reference.objective) / abs(reference.objective) <= RELATIVE
        assert fast.iterations < reference.iterations / 2
    with pytest.raises(ValueError, match="another model"):
        comanip.Planner(model.replace(kappa=2 * model.kappa), SolverOptions(arm_library=str(path)))


@pytest.mark.slow
def test_a_library_start_that_converges_beside_the_goal_falls_back_to_the_guesses():
    """Found by benchmarks/cold_quality.py (franka_rest, problem 15): from the shipped library's best start the
    solve converges on the zero-reward plateau with the arm at rest; the minimum-jerk guesses after it must run
    and give the full search's plan."""
    model = comanip.presets.load("franka_rest")
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    goal, width = hand + [-0.06353953, -0.18362716, -0.21501866], 0.02931813557924495
    plan = comanip.Planner(model).solve(start, goal, width)
    reference = comanip.Planner(model, SolverOptions(cold_search="all")).solve(start, goal, width)
    assert plan.success and reference.success
    assert abs(plan.objective - reference.objective) <= RELATIVE * abs(reference.objective)


@pytest.mark.slow
def test_a_warm_solve_from_the_ready_pose_also_starts_from_the_library():
    """With a warm start to a goal 7 cm away, the library's nearest plan competes with the warm plan as the start:
    the plan equals the one solved from the warm start alone (a planner without the library), in no more
    Newton iterations."""
    model = comanip.presets.load("franka_rest")
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    with_library, without = comanip.Planner(model), comanip.Planner(model, SolverOptions(cold_search="all"))
    assert with_library.starts.arm_library is not None and without.starts.arm_library is None
    previous = without.solve(start, hand + [0.15, 0.1, -0.1])
    goal = previous.goal + [0.04, -0.03, 0.045]
    plan, reference = with_library.solve(start, goal, warm_start=previous), without.solve(start, goal, warm_start=previous)
    assert plan.success and reference.success
    assert abs(plan.objective - reference.objective) <= RELATIVE * abs(reference.objective)
    assert plan.iterations <= reference.iterations


@pytest.mark.slow
def test_a_cold_solve_from_a_moving_start_at_the_ready_pose_starts_from_the_library():
    """A start at the ready pose moving at up to 0.3 rad/s per joint: the library's plans with braking moves
    superposed start the solve, which ends on the full search's plan in fewer iterations."""
    model = comanip.presets.load("franka_rest")
    start = np.r_[model.body.home_position, np.linspace(0.3, -0.3, model.n)]
    hand = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    goal = hand + [0.12, -0.15, 0.08]
    plan = comanip.Planner(model).solve(start, goal)
    reference = comanip.Planner(model, SolverOptions(cold_search="all")).solve(start, goal)
    assert plan.success and reference.success
    assert (plan.objective - reference.objective) / abs(reference.objective) <= RELATIVE
    assert plan.iterations < reference.iterations / 2
