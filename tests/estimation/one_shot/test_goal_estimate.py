"""Goal estimation and the goal posterior: recovering hidden goals from observed states of plans, noisy
observations, the posterior against the truth and against Monte Carlo, the CLI, and bad input."""

import json

import numpy as np
import pytest

import comanip
from comanip.belief import sample_trajectories
from comanip.belief.propagation import linearised_step_function
from comanip.cli.main import main
from comanip.estimation import EstimatorCache, GoalEstimator, estimate_goal, goal_posterior
from comanip.estimation.observation import joint_state_covariance
from comanip.estimation.observation import observation_step

T_OBS = 0.2  # the paper's observation time (s)


@pytest.fixture(scope="module")
def planar_estimator(planar_planner):
    return GoalEstimator(planar_planner)


@pytest.fixture(scope="module")
def cartesian_estimator(cartesian_planner):
    return GoalEstimator(cartesian_planner)


def direction(degrees, elevation=0.0, d=2):
    a, e = np.radians(degrees), np.radians(elevation)
    return np.array([np.cos(a) * np.cos(e), np.sin(a) * np.cos(e), np.sin(e)])[:d]


def hidden_plan(estimator, goal, start=None):
    model = estimator.model
    start = np.zeros(2 * model.n) if start is None else np.asarray(start, dtype=float)
    plan = estimator.planner.solve(start, goal)
    assert plan.success, plan.message
    return plan


@pytest.mark.parametrize("preset, goal, start", [
    ("planar", 0.30 * direction(0), None),
    ("planar", 0.18 * direction(120), None),
    ("planar", 0.42 * direction(230), None),
    ("planar", 0.25 * direction(300), [0.05, -0.02, 0.3, -0.2]),  # already moving at the start
    ("cartesian", 0.35 * direction(20, 30, 3), None),
    ("cartesian", 0.20 * direction(160, -20, 3), None),
    ("cartesian", 0.45 * direction(270, 10, 3), None),
])
def test_observed_plan_gives_back_its_goal(request, preset, goal, start):
    estimator = request.getfixturevalue(f"{preset}_estimator")
    plan = hidden_plan(estimator, goal, start)
    n_o = observation_step(estimator.model, T_OBS)
    estimate = estimator.estimate(plan.start, plan.mean[n_o], T_OBS)
    distance = np.linalg.norm(goal - plan.ee_mean[0])
    assert estimate.success, estimate.message
    assert np.linalg.norm(estimate.goal - goal) < 0.1 * distance
    np.testing.assert_array_equal(estimate.goal, estimate.estimated_goal)
    # the estimate passes through the observation and its predicted remainder follows the hidden plan
    np.testing.assert_allclose(estimate.mean[n_o], plan.mean[n_o], atol=1e-6)
    assert np.abs(estimate.ee_mean[n_o:] - plan.ee_mean[n_o:]).max() < 0.05 * distance


def test_eq11_as_printed_falls_short_of_the_goal(planar_estimator):
    """Why the default differs from the paper: its estimator prefers goals that are cheap to reach."""
    goal = np.array([0.25, 0.15])
    plan = hidden_plan(planar_estimator, goal)
    observed = plan.mean[observation_step(planar_estimator.model, T_OBS)]
    paper = planar_estimator.estimate(plan.start, observed, T_OBS, method="paper")
    regret = planar_estimator.estimate(plan.start, observed, T_OBS, warm_start=paper)
    assert paper.success and regret.success
    assert np.linalg.norm(paper.goal) < 0.9 * np.linalg.norm(goal)
    assert np.linalg.norm(regret.goal - goal) < 1e-3 * np.linalg.norm(goal)
    # both honour the observation constraint
    n_o = paper.observed_step
    np.testing.assert_allclose(paper.mean[n_o], observed, atol=1e-6)


def test_prior_pulls_the_estimate_part_of_the_way(planar_estimator):
    goal = np.array([0.3, 0.0])
    plan = hidden_plan(planar_estimator, goal)
    observed = plan.mean[observation_step(planar_estimator.model, T_OBS)]
    offset = np.array([0.0, 0.04])
    estimate = planar_estimator.estimate(plan.start, observed, T_OBS, prior_goal=goal + offset)
    assert estimate.success
    pulled = (estimate.goal - goal) @ offset / np.linalg.norm(offset)
    assert 0.0 < pulled < np.linalg.norm(offset)
    np.testing.assert_array_equal(estimate.prior_goal, goal + offset)


def test_warm_estimate_agrees_with_cold(planar_estimator, rng):
    plan = hidden_plan(planar_estimator, np.array([0.2, 0.2]))
    n_o = observation_step(planar_estimator.model, T_OBS)
    first = planar_estimator.estimate(plan.start, plan.mean[n_o], T_OBS)
    observed = plan.mean[n_o] + rng.multivariate_normal(np.zeros(4), plan.cov[n_o])
    warm = planar_estimator.estimate(plan.start, observed, T_OBS, warm_start=first)
    cold = planar_estimator.estimate(plan.start, observed, T_OBS)
    assert warm.success and cold.success
    np.testing.assert_allclose(warm.goal, cold.goal, atol=1e-6)
    assert warm.iterations <= cold.iterations + 2


def noisy_estimate_errors(estimator, goals, prior_offset, rng, warm_from_prior):
    """Relative goal errors, along-track and cross-track errors (m) of estimates from observations
    perturbed by motor noise drawn from each plan's covariance at t_obs."""
    n_o = observation_step(estimator.model, T_OBS)
    errors, along, across = [], [], []
    for goal in goals:
        plan = hidden_plan(estimator, goal)
        observed = rng.multivariate_normal(plan.mean[n_o], plan.cov[n_o])
        prior = None if prior_offset is None else goal + prior_offset * rng.normal(size=len(goal)) / np.sqrt(len(goal))
        warm = estimator.planner.solve(plan.start, prior, warm_start=plan) if warm_from_prior else None
        estimate = estimator.estimate(plan.start, observed, T_OBS, prior_goal=prior, warm_start=warm, prior_std=prior_offset)
        assert estimate.success, estimate.message
        assert np.all(np.isfinite(estimate.goal)) and np.all(np.isfinite(estimate.torque))
        error, u = estimate.goal - goal, goal / np.linalg.norm(goal)
        errors.append(np.linalg.norm(error) / np.linalg.norm(goal))
        along.append(abs(error @ u))
        across.append(np.linalg.norm(error - (error @ u) * u))
    return np.array(errors), np.array(along), np.array(across)


def test_noisy_observations_degrade_gracefully(planar_estimator, cartesian_estimator, rng):
    planar_goals = [D * direction(a) for D, a in zip(np.linspace(0.15, 0.45, 8), np.linspace(0, 315, 8))]
    errors, _, _ = noisy_estimate_errors(planar_estimator, planar_goals, None, rng, warm_from_prior=False)
    print(f"\nplanar, no prior: relative goal error median {np.median(errors):.3f}, 90 % {np.quantile(errors, 0.9):.3f}, max {errors.max():.3f}")
    assert np.median(errors) < 0.1 and errors.max() < 0.3
    # On the Cartesian preset t_obs = 0.2 s is step 3 of a reach lasting about a second: the observed state
    # fixes the direction but hardly the distance (it changes by a fraction of the noise's std between
    # 0.2 m and 0.4 m goals), so a prior decides the distance and the estimate must stay near the line.
    cartesian_goals = [0.3 * direction(a, e, 3) for a, e in [(0, 0), (100, 20), (200, -30), (300, 45)]]
    errors, along, across = noisy_estimate_errors(cartesian_estimator, cartesian_goals, 0.05, rng, warm_from_prior=True)
    print(f"cartesian, prior 5 cm off: relative error median {np.median(errors):.3f}, max {errors.max():.3f}; "
          f"along-track max {1e3 * along.max():.0f} mm, cross-track max {1e3 * across.max():.0f} mm")
    assert across.max() < 0.1 and errors.max() < 0.5


def test_wall_time_budget_returns_a_finite_estimate(cartesian_estimator):
    plan = hidden_plan(cartesian_estimator, np.array([0.3, 0.1, 0.1]))
    estimate = cartesian_estimator.estimate(plan.start, plan.mean[3], T_OBS, max_wall_time=1e-3)
    assert estimate.status == "max_wall_time" and not estimate.success
    assert np.all(np.isfinite(estimate.goal)) and np.all(np.isfinite(estimate.torque)) and np.isfinite(estimate.objective)


def test_observation_between_steps_uses_the_earlier_step(planar_estimator):
    model = planar_estimator.model
    assert observation_step(model, 0.2) == 10  # 0.2 / 0.02 rounds to 9.999…
    assert observation_step(model, 0.2199) == 10
    assert observation_step(model, 0.0599) == 2
    assert observation_step(model, 0.0201, allow_start=True) == 1  # a posterior may score step 1 (and 0)


def test_observation_at_step_one_holds_the_velocity_and_reports_the_position(planar_estimator):
    """At step 1 the position q_1 = q_0 + h qdot_0 is fixed by the start: the estimate meets the observed
    velocity, reports the position's mismatch, and a position the start cannot produce changes nothing."""
    model = planar_estimator.model
    goal = np.array([0.1, 0.25])
    plan = hidden_plan(planar_estimator, goal)
    t_obs = 1.5 * model.h
    assert observation_step(model, t_obs) == 1
    exact = planar_estimator.estimate(plan.start, plan.mean[1], t_obs)
    assert exact.success, exact.message
    assert np.linalg.norm(exact.goal - goal) < 1e-3 * np.linalg.norm(goal)  # a plan's own step-1 state gives its goal back
    offset = np.array([0.002, -0.001])
    observed = plan.mean[1] + np.r_[offset, 0.0, 0.0]
    shifted = planar_estimator.estimate(plan.start, observed, t_obs, warm_start=exact)
    assert shifted.success, shifted.message
    np.testing.assert_allclose(shifted.goal, exact.goal, atol=1e-9)
    np.testing.assert_allclose(shifted.observation_residual[:2], -offset, atol=1e-12)
    np.testing.assert_allclose(shifted.observation_residual[2:], 0.0, atol=1e-9)


def test_observation_at_step_zero_gives_the_plan_to_the_prior(planar_estimator):
    """Before h the observed state is the start itself: no information about the goal, so the estimate is
    the prior goal with its plan, flagged 'uninformative' (not a success: nothing was estimated)."""
    model = planar_estimator.model
    start, prior = np.zeros(4), np.array([0.25, -0.1])
    observed = np.array([0.001, 0.0, 0.0, 0.0])
    estimate = planar_estimator.estimate(start, observed, 0.5 * model.h, prior_goal=prior)
    assert estimate.status == "uninformative" and not estimate.success
    np.testing.assert_array_equal(estimate.goal, prior)
    np.testing.assert_array_equal(estimate.estimated_goal, prior)
    assert estimate.observed_step == 0
    np.testing.assert_allclose(estimate.observation_residual, start - observed)
    plan = planar_estimator.planner.solve(start, prior)
    np.testing.assert_allclose(estimate.ee_mean, plan.ee_mean, atol=1e-9)
    assert np.linalg.norm(estimate.ee_mean[-1] - prior) < model.width


def test_joint_state_covariance_matches_monte_carlo(planar_planner, rng):
    """Cross-covariances of the states at several steps (the posterior's likelihood) against samples."""
    model = planar_planner.model
    plan = planar_planner.solve(np.zeros(4), [0.25, -0.1])
    steps = np.array([3, 8, 8, 15])
    samples = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 4000, rng, model.noise)
    stacked = samples[:, steps].reshape(len(samples), -1)
    empirical = np.cov(stacked, rowvar=False)
    predicted = joint_state_covariance(plan, steps, linearised_step_function(model.body, model.h))
    scale = np.sqrt(np.outer(np.diag(predicted), np.diag(predicted)))
    assert np.abs(empirical - predicted).max() / scale.max() < 0.08
    np.testing.assert_allclose(np.diag(empirical), np.diag(predicted), rtol=0.1)


@pytest.mark.parametrize("preset, candidates, times", [
    ("planar", [[0.3, 0.0], [0.2, 0.15], [0.3, 0.15], [0.1, -0.1]], np.arange(1, 11) * 0.02),
    ("cartesian", [[0.3, 0.0, 0.0], [0.3, 0.1, 0.0], [0.2, 0.0, 0.1], [0.4, 0.0, 0.0], [0.25, -0.15, 0.05]], np.arange(1, 11) * 0.055),
])
def test_posterior_finds_the_true_candidate_and_sharpens(request, preset, candidates, times, rng):
    planner = request.getfixturevalue(f"{preset}_planner")
    model = planner.model
    candidates = np.array(candidates)
    separation = min(np.linalg.norm(a - b) for i, a in enumerate(candidates) for b in candidates[i + 1:])
    assert separation >= 0.1 - 1e-12
    start = np.zeros(2 * model.n)
    steps = [observation_step(model, t, allow_start=True) for t in times]
    posterior, hits, entropies = None, 0, []
    trials_per_goal = 6
    for truth in range(len(candidates)):
        plan = planner.solve(start, candidates[truth])
        samples = sample_trajectories(model.body, model.h, model.kappa, start, plan.torque, trials_per_goal, rng, model.noise)
        for states in samples[:, steps]:
            posterior = goal_posterior(planner, start, states, times, candidates, warm_start=posterior)
            np.testing.assert_allclose(posterior.probabilities.sum(axis=1), 1.0)
            hits += posterior.most_likely[-1] == truth
            entropies.append(posterior.entropy)
    trials = len(candidates) * trials_per_goal
    mean_entropy = np.mean(entropies, axis=0)
    print(f"\n{preset}: true candidate most probable in {hits}/{trials}; mean entropy {np.round(mean_entropy, 3).tolist()} nats")
    assert hits >= 0.9 * trials
    assert mean_entropy[-1] < 0.5 * mean_entropy[0]
    assert np.all(np.diff(mean_entropy) < 0.05)


def test_posterior_sees_the_start_without_singularity(planar_planner):
    """An observation at t = 0 meets Sigma_0 = 0: the observation-noise floor keeps it finite and uninformative."""
    posterior = goal_posterior(planar_planner, np.zeros(4), np.zeros((1, 4)), [0.0], [[0.3, 0.0], [0.0, 0.3]])
    np.testing.assert_allclose(posterior.probabilities, [[0.5, 0.5]])


def test_estimate_goal_function_reuses_one_estimator(planar_planner):
    model = planar_planner.model
    plan = planar_planner.solve(np.zeros(4), [0.3, 0.1])
    first = estimate_goal(model, plan.start, plan.mean[10], T_OBS)
    second = estimate_goal(model.replace(), plan.start, plan.mean[10], T_OBS, warm_start=first)
    assert first.success and second.success and second.iterations == 0


def test_cli_estimate_writes_the_estimate_posterior_and_figures(tmp_path, capsys, planar_planner):
    plan = planar_planner.solve(np.zeros(4), [0.2, 0.1])
    plan.save_csv(tmp_path / "observed.csv")
    code = main(["estimate", "--observations", str(tmp_path / "observed.csv"), "--t-obs", "0.21",
                 "--candidates", "0.2,0.1;0.3,0.1;0.2,0.25", "--out", str(tmp_path / "out"), "--png", "--verbose"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["success"]
    assert summary["observed_step"] == 10 and summary["t_obs_s"] == pytest.approx(0.2)
    np.testing.assert_allclose(summary["estimated_goal"], [0.2, 0.1], atol=0.01)
    assert summary["posterior"]["most_likely"] == 0
    for name in ("estimate.json", "estimate.csv", "estimate.png", "posterior.json", "posterior.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    saved = json.loads((tmp_path / "out" / "estimate.json").read_text())
    assert saved["method"] == "regret" and len(saved["mean"]) == 31


@pytest.mark.parametrize("kwargs, word", [
    (dict(observed=np.zeros(3)), "observed"),
    (dict(observed=[0.1, 0.0, np.nan, 0.0]), "observed"),
    (dict(t_obs=0.0), "t_obs"),
    (dict(t_obs=0.01), "prior_goal"),  # step 0 says nothing about the goal: without a prior there is no estimate
    (dict(t_obs=0.6), "t_obs"),
    (dict(t_obs=-0.1), "t_obs"),
    (dict(t_obs=float("nan")), "t_obs"),
    (dict(prior_goal=[0.3]), "prior_goal"),
    (dict(prior_goal=[np.inf, 0.0]), "prior_goal"),
    (dict(width=0.0), "width"),
    (dict(start=np.zeros(5)), "start"),
    (dict(method="newton"), "method"),
    (dict(max_wall_time=0.0), "max_wall_time"),
    (dict(warm_start=np.zeros((30, 2))), "warm_start"),
])
def test_bad_estimate_input_names_the_argument(planar_estimator, kwargs, word):
    args = dict(start=np.zeros(4), observed=[0.1, 0.0, 1.0, 0.0], t_obs=T_OBS) | kwargs
    with pytest.raises(ValueError, match=word):
        planar_estimator.estimate(**args)


@pytest.mark.parametrize("kwargs, word", [
    (dict(candidate_goals=np.zeros((0, 2))), "candidate_goals"),
    (dict(candidate_goals=[]), "candidate_goals"),
    (dict(candidate_goals=[[0.3, 0.0, 0.0]]), "candidate_goals"),
    (dict(candidate_goals=[[0.3, np.nan]]), "candidate_goals"),
    (dict(observed_states=np.zeros((2, 3))), "observed_states"),
    (dict(observed_states=[[0, 0, 0, 0], [0.1, 0, np.nan, 0]]), "observed_states"),
    (dict(times=[0.1, 0.05]), "times"),
    (dict(times=[0.1, 0.7]), "times"),
    (dict(times=[]), "times"),
    (dict(prior=[1.0]), "prior"),
    (dict(prior=[-1.0, 2.0]), "prior"),
    (dict(observation_std=(0.0, 0.01)), "observation_std"),
])
def test_bad_posterior_input_names_the_argument(planar_planner, kwargs, word):
    args = dict(start=np.zeros(4), observed_states=[[0, 0, 0, 0], [0.1, 0, 1, 0]], times=[0.1, 0.2],
                candidate_goals=[[0.3, 0.0], [0.0, 0.3]]) | kwargs
    with pytest.raises(ValueError, match=word):
        goal_posterior(planar_planner, **args)


def test_estimate_goal_uses_the_planner_it_is_given(planar_planner):
    """Two planners of one model with different options: each call uses its own (a cache keyed by the
    model alone once handed the first planner's estimator to the second)."""
    model = planar_planner.model
    one_iteration = comanip.Planner(model, comanip.SolverOptions(max_iterations=1))
    plan = planar_planner.solve(np.zeros(4), [0.3, 0.1])
    by_a = GoalEstimator(planar_planner).estimate(plan.start, plan.mean[10], T_OBS)
    by_b = GoalEstimator(one_iteration).estimate(plan.start, plan.mean[10], T_OBS)
    assert (by_a.iterations, by_a.status) != (by_b.iterations, by_b.status) or not np.array_equal(by_a.goal, by_b.goal)
    cache = EstimatorCache()
    for planner, expected in ((planar_planner, by_a), (one_iteration, by_b)):
        for estimate in (estimate_goal(planner, plan.start, plan.mean[10], T_OBS),
                         estimate_goal(planner, plan.start, plan.mean[10], T_OBS, cache=cache)):
            assert (estimate.iterations, estimate.status) == (expected.iterations, expected.status)
            np.testing.assert_array_equal(estimate.goal, expected.goal)
