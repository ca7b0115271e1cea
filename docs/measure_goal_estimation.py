"""The numbers of the README section "Goal estimation" on the goal's uncertainty and the prior (issue 12).

1. Calibration of the online estimator's goal covariance: reaches from rest to goals 0.15–0.45 m away in
   random directions, sampled from the model's own noisy dynamics (open loop, as the belief assumes; between
   grid steps the sampled states are interpolated linearly), observed every 23 ms from 11 ms on with the
   default noise (1 mm, 1 cm/s), default (weak) prior. Prints, at 0.1, 0.2, 0.3 and 0.5 s, the fraction of
   reaches whose true goal lies inside the 95 % ellipsoid of the estimate (chi-square, d degrees of freedom)
   and the median goal error.
2. Exact observation with a rough prior: five Cartesian reaches 0.2–0.45 m, a prior goal 0.2–0.45 m off, the
   plan's own state at 0.165 s (step 3) observed exactly. Prints the largest error (% of the distance) of
   the one-shot estimate and the online estimator with the default prior, and of the one-shot estimate with
   the paper's weighting (prior_std="width").

    PYTHONPATH=src python docs/measure_goal_estimation.py [--reaches 200] [--presets cartesian,planar]
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.stats import chi2

import comanip
from comanip.belief import sample_trajectories
from comanip.estimation import GoalEstimator, OnlineGoalEstimator

CHECK_TIMES = (0.1, 0.2, 0.3, 0.5)   # s, within both presets' horizons (planar: 0.6 s)


def random_goal(rng, low: float, high: float, d: int) -> np.ndarray:
    u = rng.normal(size=d)
    return rng.uniform(low, high) * u / np.linalg.norm(u)


def calibration(preset: str, reaches: int, seed: int = 1) -> dict:
    model = comanip.presets.load(preset)
    n, d = model.n, model.d
    start = np.zeros(model.state_size)
    planner = OnlineGoalEstimator(model, start).planner
    rng = np.random.default_rng(seed)
    noise = np.r_[np.full(n, 1e-3), np.full(n, 1e-2)]
    times = np.arange(0.011, max(CHECK_TIMES) + 0.012, 0.023)
    inside = {t: [] for t in CHECK_TIMES}
    errors = {t: [] for t in CHECK_TIMES}
    for _ in range(reaches):
        goal = random_goal(rng, 0.15, 0.45, d)
        plan = planner.solve(start, goal)
        states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
        estimator = OnlineGoalEstimator(model, start)
        for t in times:
            i = min(int(t / model.h), model.H - 1)
            f = t / model.h - i
            y = ((1 - f) * states[i] + f * states[i + 1])[:2 * n] + rng.normal(size=2 * n) * noise
            estimate = estimator.update(t, y[:n], y[n:])
            for at in CHECK_TIMES:
                if abs(t - at) < 0.0115:
                    error = estimate.goal - goal
                    inside[at].append(error @ np.linalg.solve(estimate.goal_covariance, error) <= chi2.ppf(0.95, d))
                    errors[at].append(np.linalg.norm(error))
    return {at: (float(np.mean(inside[at])), float(np.median(errors[at]))) for at in CHECK_TIMES}


def exact_observation(seed: int = 12) -> dict:
    model = comanip.presets.cartesian()
    one_shot = GoalEstimator(model)
    rng = np.random.default_rng(seed)
    out = {"one-shot, default prior": [], "online, default prior": [], "one-shot, prior_std='width' (paper)": []}
    for _ in range(5):
        goal = random_goal(rng, 0.2, 0.45, 3)
        offset = rng.normal(size=3)
        prior = goal + rng.uniform(0.2, 0.45) * offset / np.linalg.norm(offset)
        observed = one_shot.planner.solve(np.zeros(6), goal).mean[3]
        D = np.linalg.norm(goal)
        estimates = [one_shot.estimate(np.zeros(6), observed, 0.165, prior_goal=prior),
                     OnlineGoalEstimator(model, np.zeros(6), prior_goal=prior).update(0.165, observed[:3], observed[3:]),
                     one_shot.estimate(np.zeros(6), observed, 0.165, prior_goal=prior, prior_std="width")]
        for key, estimate in zip(out, estimates):
            out[key].append(100 * np.linalg.norm(estimate.goal - goal) / D)
    return {key: (min(v), max(v)) for key, v in out.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reaches", type=int, default=200, help="noisy reaches per preset (default: %(default)s)")
    parser.add_argument("--presets", default="cartesian,planar", help="comma-separated presets (default: %(default)s)")
    args = parser.parse_args()
    print("| preset | " + " | ".join(f"{t:g} s: coverage, median error" for t in CHECK_TIMES) + " |")
    print("|---|" + "---|" * len(CHECK_TIMES))
    for preset in args.presets.split(","):
        result = calibration(preset, args.reaches)
        print(f"| {preset} | " + " | ".join(f"{100 * c:.1f} %, {1e3 * e:.0f} mm" for c, e in result.values()) + " |", flush=True)
    print()
    for key, (low, high) in exact_observation().items():
        print(f"exact observation at 0.165 s, {key}: error {low:.3f}–{high:.3f} % of the distance")


if __name__ == "__main__":
    main()
