"""Plans, goal estimates and goal posteriors of a fixed set of problems, stored to pin the solvers' behaviour.

Run on the code whose behaviour is the reference (it writes ``reference_results.npz`` and
``reference_results_franka.npz`` beside this file):

    PYTHONPATH=src python tests/data/make_reference_results.py

``tests/project/test_reference_results.py`` recomputes every entry with :func:`reference_results` and compares.
Entries are named ``<case>/<quantity>``: a plan stores its objective J, torques (H, n), status and
iterations; an estimate its goal (d,), torques, normalised regret, status and iterations; a posterior its
probabilities (K, C) and log-likelihoods (K, C).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import comanip
from comanip.belief import sample_trajectories
from comanip.estimation import GoalEstimator, goal_posterior
from comanip.estimation.goal_prior import PAPER_PRIOR
from comanip.planning.planner import SolverOptions

PATH = Path(__file__).with_name("reference_results.npz")
FRANKA_PATH = Path(__file__).with_name("reference_results_franka.npz")
T_OBS = 0.2
"""Observation time of the estimates (s)."""


def _direction(degrees: float, elevation: float = 0.0, d: int = 2) -> np.ndarray:
    a, e = np.radians(degrees), np.radians(elevation)
    return np.array([np.cos(a) * np.cos(e), np.sin(a) * np.cos(e), np.sin(e)])[:d]


def _plan_entries(name: str, plan) -> dict:
    return {f"{name}/objective": np.float64(plan.objective), f"{name}/torque": plan.torque,
            f"{name}/status": np.str_(plan.status), f"{name}/iterations": np.int64(plan.iterations)}


def _estimate_entries(name: str, estimate) -> dict:
    return {f"{name}/goal": estimate.goal, f"{name}/torque": estimate.torque, f"{name}/status": np.str_(estimate.status),
            f"{name}/iterations": np.int64(estimate.iterations),
            f"{name}/regret": np.float64(_regret(estimate))}


def _regret(estimate) -> float:
    """The estimate's regret (J units); NaN for none (the code before GoalEstimate kept it in ``extras``)."""
    regret = estimate.extras["regret"] if "regret" in estimate.extras else getattr(estimate, "regret", None)
    return np.nan if regret is None else regret


def _plans(planners: dict) -> dict:
    """Cold and warm solves of the point-mass presets: a plan and its re-solve after the goal moves."""
    cases = {"planar": [(np.zeros(4), 0.30 * _direction(0), 0.02), (np.zeros(4), 0.18 * _direction(120), None),
                        (np.array([0.05, -0.02, 0.3, -0.2]), 0.25 * _direction(300), None)],
             "cartesian": [(np.zeros(6), 0.35 * _direction(20, 30, 3), 0.05), (np.zeros(6), 0.20 * _direction(160, -20, 3), None)],
             "human": [(np.zeros(4), 0.30 * _direction(0), None), (np.zeros(4), 0.20 * _direction(200), None)]}
    out = {}
    for preset, problems in cases.items():
        planner = planners[preset]
        for k, (start, goal, width) in enumerate(problems):
            cold = planner.solve(start, goal, width)
            warm = planner.solve(start, goal + 0.01, width, warm_start=cold)
            out.update(_plan_entries(f"plan/{preset}/{k}/cold", cold))
            out.update(_plan_entries(f"plan/{preset}/{k}/warm", warm))
    return out


def _estimates(planners: dict) -> dict:
    """Estimates from one exact observation of a plan: cold, with a prior, and warm from the plan to the prior."""
    cases = {"planar": [0.30 * _direction(0), 0.42 * _direction(230)], "cartesian": [0.35 * _direction(20, 30, 3)]}
    out = {}
    for preset, goals in cases.items():
        estimator = GoalEstimator(planners[preset])
        model = estimator.model
        n_o = int(T_OBS / model.h)
        for k, goal in enumerate(goals):
            plan = estimator.planner.solve(np.zeros(2 * model.n), goal)
            observed = plan.mean[n_o]
            prior = goal + 0.05 * _direction(90, 0, model.d)
            out.update(_estimate_entries(f"estimate/{preset}/{k}/cold", estimator.estimate(plan.start, observed, T_OBS)))
            # the stored estimates weigh the prior with W from the width (prior_std="width")
            out.update(_estimate_entries(f"estimate/{preset}/{k}/prior",
                                         estimator.estimate(plan.start, observed, T_OBS, prior, prior_std=PAPER_PRIOR)))
            prior_plan = estimator.planner.solve(plan.start, prior)
            out.update(_estimate_entries(f"estimate/{preset}/{k}/warm",
                                         estimator.estimate(plan.start, observed, T_OBS, prior, warm_start=prior_plan,
                                                            prior_std=PAPER_PRIOR)))
    return out


def _posteriors(planners: dict) -> dict:
    """Posteriors over four planar candidates from sampled executions of the plan to one of them."""
    planner = planners["planar"]
    model = planner.model
    candidates = np.array([[0.3, 0.0], [0.2, 0.15], [0.3, 0.15], [0.1, -0.1]])
    times = np.arange(1, 11) * 0.02
    steps = np.floor(times / model.h + 1e-9).astype(int)
    plan = planner.solve(np.zeros(4), candidates[2])
    samples = sample_trajectories(model.body, model.h, model.kappa, np.zeros(4), plan.torque, 2,
                                  np.random.default_rng(12345), model.noise)
    out, previous = {}, None
    for k, states in enumerate(samples[:, steps]):
        previous = goal_posterior(planner, np.zeros(4), states, times, candidates, warm_start=previous)
        out[f"posterior/planar/{k}/probabilities"] = previous.probabilities
        out[f"posterior/planar/{k}/log_likelihoods"] = previous.log_likelihoods
    return out


def reference_results() -> dict[str, np.ndarray]:
    """Every point-mass entry, computed by the code as it is (seconds).

    Cold solves run every initial guess (``cold_search="all"``, the search the entries were made with); the
    default ranked search reaches the same objectives (tests/planning/test_reach_library.py) in fewer iterations."""
    options = SolverOptions(cold_search="all")
    planners = {name: comanip.Planner(getattr(comanip.presets, name)(), options) for name in ("planar", "cartesian", "human")}
    return {**_plans(planners), **_estimates(planners), **_posteriors(planners)}


def franka_reference_results() -> dict[str, np.ndarray]:
    """The Panda's entries: a cold plan with a binding joint limit, a warm re-plan to another goal, and the
    estimates warm-started from the first and from the plan to a prior goal 3 cm off (a minute to compile
    the terms on first use, then seconds). The solver runs as the entries were made: the cold plan from every
    initial guess (``cold_search="all"``; the default starts from the shipped reach library), the Hessian
    assembled at every iteration and the tolerance 1e-8 (``hessian_refresh=1, arm_tolerance=None``; the defaults
    reach the same plans to about 1e-9 relative in J in fewer, cheaper iterations, studies/which_newton_options_suit_the_arm/compare_solver_options.py, but the
    paper preset's plans lie on a flat valley where any change of rounding moves iteration counts)."""
    options = SolverOptions(cold_search="all", hessian_refresh=1, arm_tolerance=None)
    planner = comanip.Planner(comanip.presets.franka(), options)
    model = planner.model
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    home = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    cold = planner.solve(start, home + [0.0, -0.25, 0.0])
    warm = planner.solve(start, home + [0.1, 0.1, -0.15], warm_start=cold)
    estimator, observed = GoalEstimator(planner), cold.mean[int(T_OBS / model.h)]
    estimate = estimator.estimate(start, observed, T_OBS, warm_start=cold)
    prior_plan = planner.solve(start, home + [0.02, -0.23, -0.02], warm_start=cold)
    from_prior = estimator.estimate(start, observed, T_OBS, warm_start=prior_plan)
    return {**_plan_entries("franka/cold", cold), **_plan_entries("franka/warm", warm), **_estimate_entries("franka/estimate", estimate),
            **_plan_entries("franka/prior_plan", prior_plan), **_estimate_entries("franka/estimate_from_prior", from_prior)}


if __name__ == "__main__":
    results = reference_results()
    np.savez_compressed(PATH, **results)
    franka = franka_reference_results()
    np.savez_compressed(FRANKA_PATH, **franka)
    results.update(franka)
    print(f"{len(results)} entries written to {PATH}")
