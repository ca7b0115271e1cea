"""Replanning on a budget (comanip.planning.replanner): the shift to a cycle's time against the plan it moves, the
statuses of cycles whose answer is known, and a one-iteration loop's executed cost against the converged loop's."""

import numpy as np
import pytest

import comanip
from comanip.execution import execute_receding_horizon, executed_cost
from comanip.optim import Progress
from comanip.planning.replanner import Replan, Replanner, shifted_torques
from comanip.planning.solver_options import SolverOptions

GOAL, WIDTH = np.array([0.3, 0.1]), 0.02


def test_a_whole_step_shift_drops_the_first_steps_and_holds_the_last_torque():
    torque = np.arange(12.0).reshape(6, 2)
    np.testing.assert_array_equal(shifted_torques(torque, 2.0), np.vstack([torque[2:], torque[-1:], torque[-1:]]))
    np.testing.assert_array_equal(shifted_torques(torque, 0.0), torque)
    np.testing.assert_array_equal(shifted_torques(torque, 9.5), np.repeat(torque[-1:], 6, axis=0))


def test_a_fractional_shift_is_the_plan_at_the_shifted_time():
    # torques sampled from a line at the steps' midpoints: the mean over a step moved by 0.3 of a step is the line at
    # the moved midpoint, and the integral of the shifted plan over its first steps is the old plan's from 0.3 on
    h, H = 0.02, 8
    line = lambda t: np.stack([1.0 + 5.0 * t, -2.0 * t], axis=-1)
    torque = line(h * (np.arange(H) + 0.5))
    shifted = shifted_torques(torque, 0.3)
    np.testing.assert_allclose(shifted[:-1], line(h * (np.arange(H - 1) + 0.8)), atol=1e-12)
    np.testing.assert_allclose(shifted[:-1].sum(axis=0), torque.sum(axis=0) - 0.3 * torque[0] - 0.7 * torque[-1], atol=1e-12)


def test_replanning_from_the_optimum_at_its_own_start_is_converged(planar_planner):
    replanner = Replanner(planar_planner, iterations=1)
    first = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    again = replanner.replan(first, np.zeros(4), elapsed=0.0)
    assert first.status is Progress.CONVERGED and again.status is Progress.CONVERGED
    np.testing.assert_allclose(again.torque, first.torque, atol=1e-6)
    assert again.plan.success and again.plan.torque.shape == (planar_planner.model.H, 2)


def test_one_iteration_from_a_disturbed_state_contracts_and_later_cycles_converge(planar_planner):
    replanner = Replanner(planar_planner, iterations=1)
    replan = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    disturbed = np.array([0.001, -0.001, 0.01, 0.005])
    statuses = []
    for _ in range(3):  # the same disturbed state every cycle: the iterations converge along the cycles
        replan = replanner.replan(replan, disturbed, elapsed=0.0)
        statuses.append(replan.status)
    assert statuses == [Progress.CONVERGING, Progress.CONVERGING, Progress.CONVERGED]
    converged = planar_planner.solve(disturbed, GOAL, WIDTH)
    assert replan.plan.objective == pytest.approx(converged.objective, rel=1e-8)


def test_far_from_the_optimum_the_iterations_do_not_contract(planar_planner):
    # a start moving at 0.1 m/s the plan does not expect: where the shifted plan lies the Hessian is indefinite, the
    # regularised steps are short, and the gradient grows step after step while the objective falls
    replanner = Replanner(planar_planner, iterations=1)
    first = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    pushed = np.array([0.01, -0.01, 0.1, 0.05])
    once = replanner.replan(first, pushed, elapsed=0.0)
    twice = replanner.replan(once, pushed, elapsed=0.0)
    assert once.status is Progress.NOT_CONTRACTING and twice.status is Progress.NOT_CONTRACTING
    assert once.contraction > 1 and twice.plan.objective < once.plan.objective
    assert once.plan.objective < planar_planner.problem.objective_value(first.torque, pushed, GOAL, WIDTH)


def test_a_one_iteration_loop_costs_what_the_converged_loop_costs(planar_planner):
    # 100 Hz on h = 0.02 s (half a step per cycle), the goal jumping 5 cm mid-reach, no motor noise: what differs is
    # the replanning alone (with noise one run's cost moves by percents with the noise it meets)
    loops = {}
    for name, iterations in (("converged", None), ("one iteration", 1)):
        replanner = Replanner(planar_planner, iterations=iterations)
        run = execute_receding_horizon(replanner, np.zeros(4), GOAL, WIDTH, noise=False, period=0.01, steps=90,
                                       goal_jumps=[(0.18, GOAL + [0.0, 0.05])])
        loops[name] = (run, executed_cost(planar_planner, run, WIDTH))
    (converged, cost), (fast, fast_cost) = loops["converged"], loops["one iteration"]
    assert converged.replan_statuses[1:] == ["converged"] * (len(converged.replan_statuses) - 1)
    assert "converging" in fast.replan_statuses and fast.failed_replans > 0
    assert abs(fast_cost - cost) <= 5e-3 * abs(cost)
    for run in (converged, fast):
        np.testing.assert_allclose(run.goals[-1], GOAL + [0.0, 0.05])
        assert np.linalg.norm(run.ee[-1] - run.goals[-1]) <= 0.5 * WIDTH


def test_a_budget_too_small_for_an_iteration_still_runs_the_real_time_iteration(planar_planner):
    replanner = Replanner(planar_planner, iterations=None, max_wall_time=1e-9)
    first = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    state = np.array([0.01, 0.0, 0.2, 0.0])
    late = replanner.replan(first, state, elapsed=0.01)
    assert late.iterations == 1 and late.wall_time > 1e-9
    shifted = planar_planner.problem.objective_value(shifted_torques(first.torque, 0.5), state, GOAL, WIDTH)
    assert np.isfinite(late.plan.objective) and late.plan.objective < shifted


def test_a_loop_on_a_budget_too_small_for_an_iteration_ends_where_the_converged_loop_ends(planar_planner):
    # every cycle overruns its budget by its one iteration: the iterations converge along the loop, and the executed
    # cost is the converged loop's within 0.2 % of |J_best| (a loop that sent the shifted plan whenever the budget
    # ran out would drift from it)
    runs = {}
    for name, replanner in (("converged", Replanner(planar_planner, iterations=None)),
                            ("budget", Replanner(planar_planner, iterations=None, max_wall_time=1e-9))):
        run = execute_receding_horizon(replanner, np.zeros(4), GOAL, WIDTH, noise=False, period=0.01, steps=90,
                                       goal_jumps=[(0.18, GOAL + [0.0, 0.05])])
        runs[name] = (run, executed_cost(planar_planner, run, WIDTH))
    (converged, cost), (budgeted, budgeted_cost) = runs["converged"], runs["budget"]
    assert set(budgeted.replan_iterations[1:]) == {1}
    scale = planar_planner.problem.normaliser(WIDTH)
    assert abs(budgeted_cost - cost) <= 2e-3 * scale
    assert np.linalg.norm(budgeted.ee[-1] - converged.ee[-1]) <= 1e-3


def test_bad_arguments_are_named_before_any_work(planar_planner):
    ipopt = comanip.Planner(planar_planner.model, SolverOptions(method="ipopt"))
    with pytest.raises(ValueError, match="method 'ipopt'"):
        Replanner(ipopt)
    with pytest.raises(ValueError, match="iterations"):
        Replanner(planar_planner, iterations=0)
    replanner = Replanner(planar_planner)
    first = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    with pytest.raises(ValueError, match="elapsed"):
        replanner.replan(first, np.zeros(4), elapsed=-0.01)
    with pytest.raises(ValueError, match="previous must be the Replan"):
        replanner.replan(first.torque, np.zeros(4), elapsed=0.01)
    with pytest.raises(ValueError, match="start"):
        replanner.replan(first, np.zeros(3), elapsed=0.01)
    assert isinstance(first, Replan)


def test_an_arm_cycle_evaluates_its_status_when_read_and_it_is_the_status_at_its_plan():
    """franka_rest, one iteration from a disturbed state: the cycle leaves the gradient at its plan to the first read
    of its status; read, the optimality is max |∇J| at the plan's torques from an evaluation of its own (no limit
    binds), the status compares it with the shifted plan's, and the plan's belief is that of an evaluation of its own."""
    planner = comanip.Planner(comanip.presets.load("franka_rest"))
    replanner = Replanner(planner, iterations=1)
    body = planner.model.body
    start = np.r_[body.home_position, np.zeros(body.n)]                      # the ready pose, at rest
    hand = np.asarray(body.kinematics_function(body.home_position)[0]).ravel()
    first = replanner.first_plan(start, hand + [0.1, 0.05, -0.05], 0.02)
    disturbed = first.params.start.copy()
    disturbed[planner.model.n:2 * planner.model.n] += 0.05                    # joint velocities, rad/s
    replan = replanner.replan(first, disturbed, elapsed=0.01)
    assert "outcome" not in vars(replan)                                      # nothing read yet: not evaluated
    curvature = planner.solver.curvature
    own = curvature.evaluate(np.ravel(replan.torque), replan.params)
    assert replan.optimality == pytest.approx(np.abs(own.gradient).max(), rel=1e-9)
    expected = Progress.CONVERGING if replan.optimality < replan.start_optimality else Progress.NOT_CONTRACTING
    assert replan.status is expected and replan.solver_status == "max_iterations" and replan.iterations == 1
    reference = planner.solver.make_plan(replan.torque, replan.params, status="max_iterations", success=False, message="",
                                         solve_time=0.0, iterations=1)
    np.testing.assert_allclose(replan.plan.mean, reference.mean, atol=1e-12)
    np.testing.assert_allclose(replan.plan.cov, reference.cov, atol=1e-12)
    assert replan.plan.objective == pytest.approx(reference.objective, rel=1e-12)
    # on a wall budget too small for a second iteration, a later cycle's wall budget stops it on such a point
    budgeted = Replanner(planner, iterations=None, max_wall_time=1e-9)
    second = budgeted.replan(budgeted.replan(first, disturbed, elapsed=0.01), disturbed, elapsed=0.0)
    assert second.solver_status == "max_wall_time" and second.iterations == 1
    own = curvature.evaluate(np.ravel(second.torque), second.params)
    assert second.optimality == pytest.approx(np.abs(own.gradient).max(), rel=1e-9)


def _counting_hessians(planner, monkeypatch) -> list:
    """Counts the Hessian assemblies of the planner's Newton terms until the test ends (one entry per assembly)."""
    curvature, calls = planner.solver.curvature, []
    assemble = curvature.hessian

    def counted(data):
        calls.append(1)
        return assemble(data)

    monkeypatch.setattr(curvature, "hessian", counted)
    return calls


@pytest.mark.parametrize("preset", ["planar", "franka_rest"])
def test_a_prepared_cycle_at_the_predicted_state_takes_the_iterates_of_one_that_assembles_its_own(preset, monkeypatch):
    """A cycle that measures the state its preparation predicted (the body's step under tau_0, as a loop without
    motor noise executes it) steps with the prepared Hessian, assembles none of its own, and ends on the plan of a
    cycle without preparation; a cycle whose goal moved ignores the preparation."""
    planner = comanip.Planner(comanip.presets.load(preset))
    body, period = planner.model.body, 0.01
    start = np.r_[body.home_position, np.zeros(body.n)] if preset == "franka_rest" else np.zeros(4)
    hand = np.asarray(body.kinematics_function(start[:body.n])[0]).ravel()
    goal = hand + ([0.1, 0.05, -0.05] if preset == "franka_rest" else [0.3, 0.1])
    first = Replanner(planner, iterations=1).first_plan(start, goal, 0.02)
    measured = np.asarray(body.step_function(period)(first.params.start, first.torque[0])).ravel()
    calls = _counting_hessians(planner, monkeypatch)
    alone = Replanner(planner, iterations=1).replan(first, measured, elapsed=period)
    assert len(calls) == 1
    prepared = Replanner(planner, iterations=1)
    assert prepared.prepare(first, period) > 0 and len(calls) == 2
    replan = prepared.replan(first, measured, elapsed=period)
    assert len(calls) == 2
    np.testing.assert_allclose(replan.torque, alone.torque, rtol=0, atol=1e-9 * np.abs(alone.torque).max())
    assert replan.status is alone.status
    prepared.prepare(replan, period)
    prepared.replan(replan, measured, elapsed=period, goal=goal + 0.01)
    assert len(calls) == 4  # the preparation's and the moved cycle's own


def test_prepared_cycles_from_a_state_off_the_prediction_converge_to_that_state_s_optimum(planar_planner):
    """The same disturbed state every cycle, each cycle prepared at a state 1 mm/s off it: the prepared curvature is
    the prediction's, the gradient the measured state's, so the cycles converge to the measured state's optimum, not
    the predicted one's."""
    replanner = Replanner(planar_planner, iterations=1)
    replan = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    disturbed, predicted = np.array([0.001, -0.001, 0.01, 0.005]), np.array([0.001, -0.001, 0.01, 0.004])
    for _ in range(6):
        replanner.prepare(replan, 0.0, state=predicted)
        replan = replanner.replan(replan, disturbed, elapsed=0.0)
    converged = planar_planner.solve(disturbed, GOAL, WIDTH)
    assert replan.status is Progress.CONVERGED
    assert replan.plan.objective == pytest.approx(converged.objective, rel=1e-8)


def test_a_preparation_is_checked_and_serves_only_the_cycle_after_its_plan(planar_planner, monkeypatch):
    replanner = Replanner(planar_planner, iterations=1)
    first = replanner.first_plan(np.zeros(4), GOAL, WIDTH)
    with pytest.raises(ValueError, match="elapsed"):
        replanner.prepare(first, -0.01)
    with pytest.raises(ValueError, match="replan must be a Replan"):
        replanner.prepare(first.torque, 0.01)
    with pytest.raises(ValueError, match="start"):
        replanner.prepare(first, 0.01, state=np.zeros(3))
    other = replanner.replan(first, np.zeros(4), elapsed=0.0)
    calls = _counting_hessians(planar_planner, monkeypatch)
    replanner.prepare(other, 0.01)
    replanner.replan(first, np.zeros(4), elapsed=0.01)  # not the prepared plan's successor: assembles its own
    assert len(calls) == 2
