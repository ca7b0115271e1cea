"""The human-model extensions: activation stages, the 'hit' reward, the effective width and the stopping
cost, each through the belief propagation (closed form against Monte Carlo) and the fast Newton solver
(structured Hessian against CasADi's exact one)."""

import casadi as ca
import numpy as np
import pytest
from scipy.special import gammaincc, gammaincinv

import comanip
from comanip.belief import propagate_belief, sample_trajectories
from comanip.bodies import MuscleActuatedBody
from comanip.objectives.reward import HIT_KERNEL_ORDER, GoalReward, goal_covariance
from comanip.planning.curvature import ReachCurvature
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_parameters import ReachParameters

FILTERED = dict(activation=(0.04, 0.03))


def test_activation_belief_matches_monte_carlo(rng):
    """Mean and covariance of the filtered, noisy plant, closed form against 40 000 executions."""
    model = comanip.presets.planar().replace(**FILTERED, H=15)
    torque = rng.normal(scale=4.0, size=(model.H, 2))
    s0 = model.full_state(np.r_[0.0, 0.0, 0.2, -0.1])
    mean, cov = propagate_belief(model.body, model.h, model.kappa, s0, torque, model.noise)
    samples = sample_trajectories(model.body, model.h, model.kappa, s0, torque, 40_000, rng, model.noise)
    assert mean.shape == (model.H + 1, model.state_size) == (16, 8)
    np.testing.assert_allclose(samples.mean(axis=0), mean, atol=4 * np.sqrt(cov.diagonal(axis1=1, axis2=2).max() / 40_000) + 1e-12)
    for i in (5, 10, 15):
        sample_cov = np.cov(samples[:, i].T)
        np.testing.assert_allclose(np.diag(sample_cov), np.diag(cov[i]), rtol=0.02)
    # the noise enters at the command: the force stages are noisy, and the position only after them
    assert cov[1, :4, :4].max() == 0 and cov[1, 4:6, 4:6].max() > 0


def test_command_for_force_inverts_the_activation_stages(rng):
    body = MuscleActuatedBody(comanip.bodies.PointMass(2), (0.04, 0.02))
    force = np.cumsum(rng.normal(size=(20, 2)), axis=0)
    force[:2] = 0.0  # two stages from rest: the first two forces are zero whatever the command
    command = body.command_for_force(force, 0.02)
    state = np.zeros(body.state_size)
    step = ca.Function("step", [s := ca.SX.sym("s", body.state_size), u := ca.SX.sym("u", 2)], [body.discrete_step(s, u, 0.02)])
    felt = []
    for u_k in command:
        felt.append(state[-2:].copy())
        state = np.asarray(step(state, u_k)).ravel()
    np.testing.assert_allclose(np.array(felt), force, atol=1e-9)


def test_hit_reward_closed_form_matches_monte_carlo_of_its_kernel(rng):
    """E[K(||x - g||)] in closed form against 200 000 samples, 2-D and 3-D, anisotropic and off-centre."""
    m = HIT_KERNEL_ORDER
    for d in (2, 3):
        reward = GoalReward(d, "hit")
        w = 0.02
        s2 = w**2 / (2 * gammaincinv(m + 1, 0.5))
        for sigma, offset in [(0.3, 0.0), (0.4, 0.5), (0.6, 0.2), (0.5, 1.5)]:
            L = rng.normal(scale=0.4, size=(d, d)) + np.eye(d)
            S = (sigma * w) ** 2 * d * L @ L.T / np.trace(L @ L.T)
            mu = np.r_[offset * w, np.zeros(d - 1)]
            x = rng.multivariate_normal(mu, S, 200_000)
            kernel = gammaincc(m + 1, np.sum(x**2, axis=1) / (2 * s2))
            assert reward.expected(mu, S, np.zeros(d), w) == pytest.approx(kernel.mean(), abs=0.01)


def test_hit_reward_saturates_and_reads_w_as_a_radius():
    reward = GoalReward(2, "hit")
    w = 0.01
    centred = [reward.expected(np.zeros(2), (s * w) ** 2 * np.eye(2), np.zeros(2), w) for s in (0.0, 0.1, 0.2, 0.5, 1.0)]
    assert centred[0] == pytest.approx(1.0, abs=1e-12) and centred[1] > 0.999  # flat inside: precision earns nothing more
    assert np.all(np.diff(centred) < 0)
    assert reward.expected(np.r_[w, 0.0], np.zeros((2, 2)), np.zeros(2), w) == pytest.approx(0.5, abs=1e-9)  # the edge
    assert reward.expected(np.r_[3 * w, 0.0], np.zeros((2, 2)), np.zeros(2), w) < 1e-3
    gaussian = GoalReward(2, "gaussian")
    gaussian_loss = 1 - gaussian.expected(np.zeros(2), (0.2 * w) ** 2 * np.eye(2), np.zeros(2), w) / gaussian.peak(w)
    assert 1 - centred[2] < 0.1 * float(gaussian_loss)  # the Gaussian overlap still pays for precision there


def test_effective_width_spans_k_standard_deviations():
    np.testing.assert_allclose(goal_covariance(0.02, 2, "effective", 4.133), (0.04 / 4.133) ** 2 * np.eye(2))
    assert comanip.presets.planar().replace(goal_covariance="effective", effective_k=2.0).effective_k == 2.0
    with pytest.raises(ValueError, match="effective_k"):
        comanip.presets.planar().replace(effective_k=0.0)


@pytest.mark.parametrize("changes", [dict(FILTERED), dict(reward="hit"), dict(stop_weight=2e-3),
                                     dict(joint_velocity_weight=0.5, stop_weight=0.1),
                                     dict(FILTERED, reward="hit", stop_weight=1e-3, goal_covariance="effective"),
                                     dict(FILTERED, joint_velocity_weight=0.2)])
def test_structured_hessian_is_exact_with_the_extensions(changes, rng):
    model = comanip.presets.planar().replace(H=10, **changes)
    problem = ReachProblem(model)
    curvature = ReachCurvature(problem)
    x = ca.vec(problem.tau)
    f = problem.objective / -problem.best_objective
    exact = ca.Function("exact", [x, problem.s0, problem.goal, problem.width], [ca.hessian(f, x)[0], f])
    for _ in range(2):
        tau = rng.normal(scale=3.0, size=x.numel())
        p = ReachParameters(model.full_state(rng.normal(scale=0.1, size=4)), rng.uniform(0.05, 0.15, 2), 0.03)
        evaluation = curvature.evaluate(tau, p)
        value, data = evaluation.f, evaluation.data
        H_exact, f_exact = (np.asarray(v) for v in exact(tau, p.start, p.goal, p.width))
        assert value == pytest.approx(f_exact.item(), rel=1e-12)
        np.testing.assert_allclose(curvature.hessian(data), H_exact, rtol=1e-8, atol=1e-10 * np.abs(H_exact).max())


def test_activation_removes_the_force_step_at_the_start():
    """The paper's plan starts with a force step (speed at 50 ms a large share of the peak); filtered, it does not."""
    onsets = []
    for model in (comanip.presets.planar().replace(H=60), comanip.presets.planar().replace(H=60, **FILTERED)):
        plan = comanip.Planner(model).solve(np.zeros(4), [0.3, 0.0], 0.02)
        assert plan.success and plan.mean.shape[1] == model.state_size
        onsets.append(np.interp(0.05, plan.t, plan.ee_speed) / plan.ee_speed.max())
    assert onsets[1] < 0.1 < onsets[0]


def test_stopping_cost_slows_the_end_of_the_horizon():
    model = comanip.presets.planar().replace(H=20)
    plans = [comanip.Planner(model.replace(stop_weight=w)).solve(np.zeros(4), [0.3, 0.0], 0.02) for w in (0.0, 10.0)]
    assert all(p.success for p in plans)
    final = [np.linalg.norm(p.mean[-1, 2:4]) + np.sqrt(np.trace(p.cov[-1, 2:4, 2:4])) for p in plans]
    assert final[1] < 0.8 * final[0]


def test_running_speed_cost_slows_the_reach():
    """joint_velocity_weight penalises speed all along: the peak hand speed drops and the plan still reaches."""
    model = comanip.presets.planar()
    plans = [comanip.Planner(model.replace(joint_velocity_weight=w)).solve(np.zeros(4), [0.3, 0.0], 0.02) for w in (0.0, 0.2)]
    assert all(p.success for p in plans)
    assert plans[1].ee_speed.max() < 0.9 * plans[0].ee_speed.max()


def test_model_options_round_trip_through_yaml(tmp_path):
    model = comanip.presets.planar().replace(**FILTERED, reward="hit", goal_covariance="effective", effective_k=3.0, stop_weight=1e-3,
                                            joint_velocity_weight=0.1)
    again = comanip.presets.load(comanip.presets.save(model, tmp_path / "m.yaml"))
    assert again.config() == model.config() and isinstance(again.body, MuscleActuatedBody) and again.state_size == 8
    bare = again.replace(activation=())
    assert bare.state_size == 4 and not isinstance(bare.body, MuscleActuatedBody)
    with pytest.raises(ValueError, match="activation"):
        comanip.presets.planar().replace(activation=(0.04, -1.0))
    with pytest.raises(ValueError, match="reward"):
        comanip.presets.planar().replace(reward="box")


def test_feedback_shrinks_the_endpoint_spread_the_plan_predicts():
    """Closed loop (replanning from the state every step) ends far tighter than the open-loop plan's spread."""
    from comanip.analysis import measure_closed_loop_targets, measure_human_targets

    model = comanip.presets.planar()
    grid = dict(distances=(0.3,), widths=(0.01, 0.04))
    open_loop = measure_human_targets(model, n_samples=200, **grid)
    closed = measure_closed_loop_targets(model, n_trials=5, **grid)
    assert closed.model_name == "planar closed loop" and len(closed.rows) == 2
    for plan_row, run_row in zip(open_loop.rows, closed.rows):
        assert run_row.samples == 5 and 0 <= run_row.hit_rate_monte_carlo <= 1
        assert max(run_row.sd_along, run_row.sd_across) < 0.5 * min(plan_row.sd_along_predicted, plan_row.sd_across_predicted)


def test_model_observation_drives_the_closed_loop_estimate():
    from comanip.execution import Observation, execute_receding_horizon

    model = comanip.presets.planar().replace(observation=(0.004, 0.04, 0.1))
    assert Observation.of(model) == Observation(0.004, 0.04, 0.1) and Observation.of(comanip.presets.planar()) is None
    run = execute_receding_horizon(comanip.Planner(model), np.zeros(4), [0.2, 0.0], 0.02, steps=8, rng=np.random.default_rng(0))
    assert run.estimates is not None and not np.allclose(run.estimates[1:, :2], run.states[1:, :2])
    with pytest.raises(ValueError, match="observation"):
        comanip.presets.planar().replace(observation=(0.004, 0.04))
    with pytest.raises(ValueError, match="observation"):
        comanip.presets.planar().replace(observation=0.004)
    with pytest.raises(ValueError, match=r"observation\[2\]"):
        comanip.presets.planar().replace(observation=(0.004, 0.04, -0.1))


@pytest.mark.slow
def test_human_preset_trends():
    """What the human preset is for, as trends over the targets' grid: Fitts' law with a steeper slope than the
    paper's (a human one, about 80 ms/bit), a smooth onset and a flat t_peak/MT in the plan, and, in its closed
    loop with feedback,
    a deceleration phase that lengthens for smaller goals (t_peak/MT falls as w shrinks)."""
    from comanip.analysis import measure_closed_loop_targets, measure_human_targets

    human, paper = comanip.presets.human(), comanip.presets.planar()
    plans = {m.name: measure_human_targets(m, n_samples=100) for m in (human, paper)}
    assert plans["human"].fitts.b > 1.5 * plans["planar"].fitts.b and plans["human"].fitts.r2 >= 0.95
    assert max(r.onset for r in plans["human"].rows) < 0.15 < max(r.onset for r in plans["planar"].rows)
    assert plans["human"].asymmetry_slope < 0.5 * plans["planar"].asymmetry_slope
    closed = measure_closed_loop_targets(human, n_trials=4, distances=(0.3,), widths=(0.005, 0.04))
    small, large = closed.rows
    assert small.asymmetry < large.asymmetry - 0.05 and small.movement_time > large.movement_time


def test_a_plan_with_activation_stages_saves_a_csv_whose_header_fits_its_rows(tmp_path, activation_planner):
    import csv

    plan = activation_planner.solve(np.zeros(4), [0.3, 0.0], 0.04)
    with open(plan.save_csv(tmp_path / "plan.csv")) as f:
        rows = list(csv.reader(f))
    assert rows[0][5:9] == ["a1_0", "a1_1", "a2_0", "a2_1"]
    assert all(len(row) == len(rows[0]) for row in rows)
