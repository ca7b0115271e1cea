"""Cold solves of the point masses: the ranked start from a solved, turned reach gives the plan of the full
search over minimum-jerk guesses, and the symmetry it rests on holds."""

import numpy as np
import pytest

import comanip
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.solver_options import SolverOptions
from comanip.planning.reflection import reflection_onto
from comanip.planning.starts.reach_library import is_symmetric

RELATIVE = 1e-6
"""Objectives of the ranked and the full search agree to this (relative)."""


def _problems(model, count: int, seed: int):
    """(start (2n,), goal (d,), width): goals 0.1–0.4 m away, widths 5–50 mm, every other start moving."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        start = np.zeros(2 * model.n)
        if k % 2:
            start[model.n:] = rng.uniform(-0.3, 0.3, model.n)
        start[: model.n] = rng.uniform(-0.1, 0.1, model.n)
        direction = rng.normal(size=model.d)
        goal = start[: model.n] + rng.uniform(0.1, 0.4) * direction / np.linalg.norm(direction)
        yield start, goal, float(np.exp(rng.uniform(np.log(0.005), np.log(0.05))))


@pytest.mark.parametrize("preset, seed", [("planar", 0), ("cartesian", 1), ("human", 2)])
def test_ranked_cold_solve_is_as_good_as_the_full_search(preset, seed):
    model = comanip.presets.load(preset)
    ranked, full = comanip.Planner(model), comanip.Planner(model, SolverOptions(cold_search="all"))
    assert ranked.starts.library is not None
    for start, goal, width in _problems(model, 4, seed):
        fast, reference = ranked.solve(start, goal, width), full.solve(start, goal, width)
        assert fast.success and reference.success
        # as good as the full search (the cold-search rule allows 1e-4 in 2 % of problems; these four are closer)
        assert (fast.objective - reference.objective) / abs(reference.objective) <= RELATIVE
        motion = model.full_state(np.r_[np.zeros(model.n), start[model.n:]])
        params = ReachParameters(model.full_state(start), goal, width)
        if ranked.starts.stops(motion).any() and ranked.starts.narrow_after_stops(params, motion):  # the full search's starts
            assert fast.iterations == reference.iterations
        else:  # one solve from a near-optimal start, not every guess
            assert fast.iterations < reference.iterations


@pytest.mark.parametrize("preset, seed", [("planar", 6), ("human", 7)])
def test_far_narrow_goals_from_rest_start_from_the_library_local_optima(preset, seed):
    """Past narrow_ratio widths local optima compete (they differ in the step where the hand brakes): the ranked
    start among the library entries' optima, at several paces, ends as good as the full search or better, in one
    solve instead of every guess's."""
    model = comanip.presets.load(preset)
    ranked, full = comanip.Planner(model), comanip.Planner(model, SolverOptions(cold_search="all"))
    rng = np.random.default_rng(seed)
    for _ in range(4):
        width = float(np.exp(rng.uniform(np.log(0.005), np.log(0.02))))
        distance = rng.uniform(25, 120) * width
        direction = rng.normal(size=model.d)
        start, goal = np.zeros(2 * model.n), distance * direction / np.linalg.norm(direction)
        assert ranked.starts.narrow(ReachParameters(model.full_state(start), goal, width))
        fast, reference = ranked.solve(start, goal, width), full.solve(start, goal, width)
        assert fast.success and reference.success
        assert (fast.objective - reference.objective) / abs(reference.objective) <= RELATIVE
        assert fast.iterations < reference.iterations / 2


def test_a_reach_at_half_pace_pushes_with_a_quarter_of_the_force_and_at_pace_one_is_unchanged():
    from comanip.planning.starts.reach_library import at_pace

    torque = np.random.default_rng(8).normal(size=(30, 2))
    np.testing.assert_array_equal(at_pace(torque, 1.0), torque)
    slower = at_pace(np.ones((30, 2)), 0.5)  # a constant push run at half speed: a quarter of the force
    np.testing.assert_allclose(slower, 0.25)


def test_library_entries_do_not_depend_on_the_order_of_the_solves():
    model = comanip.presets.planar()
    problems = list(_problems(model, 3, 3))
    forward = [comanip.Planner(model).solve(*p) for p in [problems[0], problems[1], problems[2]]]
    backward = comanip.Planner(model)
    for p, plan in zip(problems[::-1], forward[::-1]):
        np.testing.assert_array_equal(backward.solve(*p).torque, plan.torque)


@pytest.mark.parametrize("preset", ["planar", "human_cartesian"])
def test_a_turned_and_shifted_plan_has_the_original_objective(preset):
    model = comanip.presets.load(preset)
    planner = comanip.Planner(model)
    plan = planner.solve(np.zeros(2 * model.n), 0.25 * np.eye(model.d)[0], 0.02)
    rng = np.random.default_rng(4)
    turn = np.linalg.qr(rng.normal(size=(model.n, model.n)))[0]
    shift = rng.normal(scale=0.1, size=model.n)
    start = np.r_[shift, np.zeros(model.state_size - model.n)]
    turned = planner.problem.objective_value(plan.torque @ turn.T, start, turn @ plan.goal + shift, 0.02)
    np.testing.assert_allclose(turned, plan.objective, rtol=1e-9)
    # and the planner, asked the turned problem cold, finds that objective (it starts from a turned library reach)
    resolved = planner.solve(start[: 2 * model.n], turn @ plan.goal + shift, 0.02)
    np.testing.assert_allclose(resolved.objective, plan.objective, rtol=RELATIVE)


def test_reflection_onto_is_orthogonal_and_takes_e1_to_the_direction():
    rng = np.random.default_rng(5)
    for d in (2, 3):
        for direction in [np.eye(d)[0], -np.eye(d)[0], rng.normal(size=d)]:
            direction = direction / np.linalg.norm(direction)
            R = reflection_onto(direction)
            np.testing.assert_allclose(R @ R.T, np.eye(d), atol=1e-12)
            np.testing.assert_allclose(R @ np.eye(d)[0], direction, atol=1e-12)


@pytest.mark.parametrize("change", [dict(noise="per_channel"), dict(goal_covariance="std")])
def test_only_symmetric_models_get_a_library(change):
    model = comanip.presets.cartesian().replace(**change)
    planner = comanip.Planner(model)
    symmetric = change.get("noise") != "per_channel"
    assert (planner.starts.library is not None) == symmetric
    assert is_symmetric(planner.problem) == symmetric
    plan = planner.solve(np.zeros(6), [0.2, 0.1, 0.0], 0.02)
    assert plan.success


def test_a_budgeted_cold_solve_does_not_solve_a_new_library_reach():
    """Solving a library entry is a whole cold search outside max_wall_time: a budgeted solve uses only entries
    solved before (and still converges from the minimum-jerk guesses), an unbudgeted one adds the entry."""
    model = comanip.presets.cartesian()
    planner = comanip.Planner(model)
    start, goal = np.zeros(6), np.array([0.1, 0.2, 0.0])
    budgeted = planner.solve(start, goal, 0.02, max_wall_time=60.0)
    assert budgeted.success and not planner.starts.library._entries
    plan = planner.solve(start, goal, 0.02)
    assert plan.success and len(planner.starts.library._entries) == 1
    np.testing.assert_allclose(budgeted.objective, plan.objective, rtol=RELATIVE)


@pytest.mark.parametrize("preset", ["planar", "cartesian", "human"])
def test_a_retargeted_plan_moves_its_mean_path_by_the_shift(preset):
    """A point mass's mean is affine in the torques: a plan retargeted by a move of ≥ 12 steps ends moved by
    the joint shift to within 4 % (the move's acceleration is sampled once per step), for a bare point mass;
    retargeting for several durations at once equals retargeting for each alone."""
    from comanip.planning.starts.initial_guess import retargeted_torques

    model = comanip.presets.load(preset)
    planner = comanip.Planner(model)
    start = model.full_state(np.zeros(2 * model.n))
    goal = np.full(model.d, 0.2)
    plan = planner.solve(start, goal, model.width)
    shift = np.linspace(0.03, -0.02, model.n)
    durations = np.array([12, 20, 0.75 * model.H]) * model.h
    moved = retargeted_torques(model.body, model.h, model.H, plan.torque, shift, durations, linear_dynamics=planner.starts.linear_dynamics)
    for T, torque in zip(durations, moved):
        alone = retargeted_torques(model.body, model.h, model.H, plan.torque, shift, [T], linear_dynamics=planner.starts.linear_dynamics)[0]
        np.testing.assert_allclose(torque, alone, rtol=1e-12, atol=1e-12)
        if not model.activation:  # activation stages lag the move (an initial guess tolerates it)
            trajectory = planner.problem.trajectory(tau=np.ravel(torque), s0=start, goal=goal, width=model.width)
            end = np.asarray(trajectory["ee_mean"])[:, -1]
            np.testing.assert_allclose(end - plan.ee_mean[-1], shift, atol=0.04 * np.abs(shift).max())


def test_minimum_jerk_profiles_meet_their_boundary_conditions_one_duration_or_several():
    from comanip.planning.starts.initial_guess import minimum_jerk

    x0, v0, x1 = np.array([0.1, -0.2]), np.array([0.3, 0.05]), np.array([0.4, 0.2])
    durations = np.array([0.2, 0.37, 0.5])
    t = np.linspace(0.0, 0.6, 601)
    together = minimum_jerk(x0, v0, x1, durations, t)
    for k, T in enumerate(durations):
        pos, vel, acc = minimum_jerk(x0, v0, x1, T, t)
        for alone, batched in zip((pos, vel, acc), together):
            np.testing.assert_array_equal(alone, batched[k])
        np.testing.assert_allclose([pos[0], vel[0], acc[0]], [x0, v0, 0 * x0], atol=1e-12)
        end = t >= T
        np.testing.assert_allclose(pos[end], np.broadcast_to(x1, pos[end].shape), atol=1e-12)
        np.testing.assert_allclose(vel[end], 0.0, atol=1e-9)
        # the velocity is the derivative of the position (central differences inside the move)
        inside = (t > 0.01) & (t < T - 0.01)
        np.testing.assert_allclose(np.gradient(pos, t, axis=0)[inside], vel[inside], atol=2e-3)


@pytest.mark.parametrize("preset", ["cartesian", "human"])
def test_a_moving_start_is_stopped_where_the_hand_comes_to_rest(preset):
    """From a moving start the candidates are stops superposed on library reaches. A lightly damped hand (Cartesian,
    D⁻¹M = 6.7 s) stops v0·T/2 on: the best such start has a lower objective than the best of the stops back at the
    start position, and its rollout from the moving start ends at rest. A strongly damped one (human, D⁻¹M = 0.13 s,
    shorter than T/2) is stopped back at the start position."""
    from comanip.planning.starts.initial_guess import guess_durations, minimum_jerk_torques

    model = comanip.presets.load(preset)
    planner = comanip.Planner(model)
    starts, n = planner.starts, model.n
    durations = guess_durations(model.duration, planner.options.n_starts)
    for velocity in (np.array([0.2, -0.15, 0.1][:n]), np.array([-0.25, 0.05, 0.2][:n])):
        start, goal = np.r_[np.zeros(n), velocity], np.array([0.3, 0.1, 0.0][:n])
        params = ReachParameters(start, goal, model.width)
        for reach in [params, *starts.stopped_starts(params, starts.stops(start))]:
            starts.library.fill(reach, bracket=False)
        stopped = starts.stopped_reaches(params, start)
        at_start = list(starts.library.guess(params)
                        + minimum_jerk_torques(model.body, model.h, model.H, start, np.zeros(n), durations, starts.linear_dynamics))
        if preset == "human":
            np.testing.assert_allclose(np.array(stopped), np.array(at_start), rtol=0, atol=1e-12)
            continue
        assert min(starts.objective(c, params) for c in stopped) < min(starts.objective(c, params) for c in at_start)
        for candidate in stopped:
            rollout = planner.problem.trajectory(tau=np.ravel(candidate), s0=start, goal=goal, width=model.width)
            assert np.linalg.norm(np.asarray(rollout["mean"])[n:2 * n, -1]) < 0.05 * np.linalg.norm(velocity)


def test_an_undamped_hand_from_a_moving_start_stops_where_a_free_end_stop_comes_to_rest():
    """Without damping nothing stops the hand but the stop itself: every stop ends v0·T/2 on, and the candidates'
    rollouts from the moving start end at rest (no infinite or undefined drift on the way)."""
    from comanip.bodies.point_mass import PointMass

    model = comanip.presets.planar().replace(body=PointMass(2, damping=0.0))
    planner = comanip.Planner(model)
    velocity = np.array([0.2, -0.1])
    start, goal = np.r_[np.zeros(2), velocity], np.array([0.25, 0.05])
    assert planner.starts.damped_drift is None
    params = ReachParameters(start, goal, model.width)
    for reach in planner.starts.stopped_starts(params, planner.starts.stops(start)):
        planner.starts.library.fill(reach, bracket=False)
    candidates = planner.starts.stopped_reaches(params, start)
    assert len(candidates) == planner.options.n_starts and all(np.all(np.isfinite(c)) for c in candidates)
    for candidate in candidates:
        rollout = planner.problem.trajectory(tau=np.ravel(candidate), s0=start, goal=goal, width=model.width)
        assert np.linalg.norm(np.asarray(rollout["mean"])[2:4, -1]) < 0.05 * np.linalg.norm(velocity)
    assert planner.solve(start, goal, model.width).success
