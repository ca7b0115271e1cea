"""The numbers of docs/results/calibration.md on the goal's uncertainty and the prior.

1. Calibration of the online estimator's goal covariance: reaches from rest to goals 0.15–0.45 m away in
   random directions, sampled from the model's own noisy dynamics (open loop, as the belief assumes; between
   grid steps the sampled states are interpolated linearly), observed every 23 ms from 11 ms on with the
   default noise (1 mm, 1 cm/s), default (weak) prior. Prints, at 0.1, 0.2, 0.3 and 0.5 s, the fraction of
   reaches whose true goal lies inside the 95 % ellipsoid of the estimate (chi-square, d degrees of freedom)
   and the median goal error.
2. The same for the sync robot's belief (the ``sync_robot`` description of comanip.estimation.streaming.online_settings: a person who
   corrects deviations, the robot-led z, the covariance scaled), on Cartesian reaches sampled from the process
   that belief assumes (the plan's mean plus errors of comanip.estimation.online.corrected_deviation, every axis the
   person's), at 0.2, 0.4, 0.6 and 0.8 s and pooled over those times; the same belief without the scale beside it.
3. Exact observation with a rough prior: five Cartesian reaches 0.2–0.45 m, a prior goal 0.2–0.45 m off, the
   plan's own state at 0.165 s (step 3) observed exactly. Prints the largest error (% of the distance) of
   the one-shot estimate and the online estimator with the default prior, and of the one-shot estimate with
   the paper's weighting (prior_std="width").

    PYTHONPATH=src python -m studies.is_the_goal_covariance_calibrated.measure_goal_estimation [--reaches 200] [--presets cartesian,planar] [--markdown]
    PYTHONPATH=src python -m studies.is_the_goal_covariance_calibrated.measure_goal_estimation --belief robot [--reaches 200] [--seed 0]   # only 2.

``--markdown`` prints the results page's block ``goal-calibration`` (tools/regenerate_results.py) instead.
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np
from scipy.stats import chi2

import comanip
from comanip.belief import sample_trajectories
from comanip.belief.propagation import linearised_step_function
from comanip.estimation import GoalEstimator, OnlineGoalEstimator, OnlineOptions
from comanip.estimation.online.corrected_deviation import correction_factor, sample_corrected_deviations
from comanip.estimation.streaming import online_settings

ROBOT_BELIEF = online_settings.load("sync_robot").options
"""The sync robot's belief (the ``sync_robot`` description)."""

CHECK_TIMES = (0.1, 0.2, 0.3, 0.5)   # s, within both presets' horizons (planar: 0.6 s)
#: When the robot's belief is checked (s): from t_o through the middle of a ~1 s Cartesian reach.
ROBOT_TIMES = (0.2, 0.4, 0.6, 0.8)


def random_goal(rng, low: float, high: float, d: int) -> np.ndarray:
    u = rng.normal(size=d)
    return rng.uniform(low, high) * u / np.linalg.norm(u)


def calibration(preset: str, reaches: int, seed: int = 1, options: OnlineOptions | None = None,
                check_times=CHECK_TIMES) -> dict:
    """{t: (coverage of the 95 % ellipsoid, median goal error m)} over ``reaches`` noisy reaches sampled from
    the belief of ``options`` (None: the open-loop model's own noisy dynamics; with a correction time: the
    plan's mean plus errors of the corrected process, comanip.estimation.online.corrected_deviation), estimated with
    those options and the default prior."""
    model = comanip.presets.load(preset)
    n, d = model.n, model.d
    start = np.zeros(model.state_size)
    planner = OnlineGoalEstimator(model, start, options=options).planner
    rng = np.random.default_rng(seed)
    noise = np.r_[np.full(n, 1e-3), np.full(n, 1e-2)]
    times = np.arange(0.011, max(check_times) + 0.012, 0.023)
    inside = {t: [] for t in check_times}
    errors = {t: [] for t in check_times}
    corrected = options is not None and options.correction_time is not None
    if corrected:
        A = np.asarray(linearised_step_function(model.body, model.h)(start, np.zeros(n))[1])
        rho = correction_factor(options.correction_time, model.h)
    for _ in range(reaches):
        goal = random_goal(rng, 0.15, 0.45, d)
        plan = planner.solve(start, goal)
        if corrected:
            states = plan.mean + sample_corrected_deviations(plan.cov, A, rho, plan.mean, options.deviation_time,
                                                             model.h, n, 1, rng)[0]
        else:
            states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
        estimator = OnlineGoalEstimator(model, start, options=options)
        for t in times:
            i = min(int(t / model.h), model.H - 1)
            f = t / model.h - i
            y = ((1 - f) * states[i] + f * states[i + 1])[:2 * n] + rng.normal(size=2 * n) * noise
            estimate = estimator.update(t, y[:n], y[n:])
            for at in check_times:
                if abs(t - at) < 0.0115:
                    error = estimate.goal - goal
                    inside[at].append(error @ np.linalg.solve(estimate.goal_covariance, error) <= chi2.ppf(0.95, d))
                    errors[at].append(np.linalg.norm(error))
    return {at: (float(np.mean(inside[at])), float(np.median(errors[at]))) for at in check_times}


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


REACH_LENGTH = {"cartesian": "reach ~1 s", "planar": "reach ~0.3–0.45 s"}


def robot_belief_calibration(reaches: int, seed: int = 0) -> dict[str, dict]:
    """{label: calibration} of the sync robot's belief (item 2 of the module docstring), with and without its
    covariance scale."""
    beliefs = {f"robot's belief (covariance × {ROBOT_BELIEF.covariance_scale:g})": ROBOT_BELIEF,
               "without the scale": dataclasses.replace(ROBOT_BELIEF, covariance_scale=1.0)}
    return {label: calibration("cartesian", reaches, seed, options, ROBOT_TIMES) for label, options in beliefs.items()}


def robot_table(results: dict[str, dict], reaches: int, seed: int) -> str:
    lines = ["| belief | " + " | ".join(f"{t:g} s" for t in ROBOT_TIMES) + " | pooled |", "|---|" + "---|" * (len(ROBOT_TIMES) + 1)]
    for label, result in results.items():
        cells = [f"{100 * c:.1f} % ({1e3 * e:.0f} mm)" for c, e in result.values()]
        pooled = 100 * float(np.mean([c for c, _ in result.values()]))
        lines.append(f"| {label} | " + " | ".join(cells) + f" | {pooled:.1f} % |")
    return "\n".join(lines) + (f"\n\n(The sync robot's belief on {reaches} Cartesian reaches sampled from the corrected process "
                               f"(seed {seed}), 95 % ellipsoid coverage and median goal error; "
                               "`studies/is_the_goal_covariance_calibrated/measure_goal_estimation.py --belief robot`.)\n")


def markdown_block(results: dict[str, dict], exact: dict, reaches: int) -> str:
    """The results page's calibration table and the exact-observation line."""
    lines = ["| preset | " + " | ".join(f"{t:g} s" for t in CHECK_TIMES) + " |", "|---|" + "---|" * len(CHECK_TIMES)]
    for preset, result in results.items():
        cells = [f"{100 * c:.1f} % ({1e3 * e:.0f} mm)" for c, e in result.values()]
        lines.append(f"| {preset} ({REACH_LENGTH.get(preset, '')}) | " + " | ".join(cells) + " |")
    low, high = exact["online, default prior"]
    one_low, one_high = exact["one-shot, default prior"]
    paper_low, paper_high = exact["one-shot, prior_std='width' (paper)"]
    lines += ["", f"(Coverage of the 95 % ellipsoid and median goal error over {reaches} reaches per preset, each estimate "
              "from all observations up to that time; `studies/is_the_goal_covariance_calibrated/measure_goal_estimation.py --markdown`.) An exact "
              f"observation at 0.165 s on the Cartesian preset with a prior 0.2–0.45 m off: online {low:.2f}–{high:.2f} %, "
              f"one-shot {one_low:.3f}–{one_high:.3f} % of the distance with the default prior; "
              f"{paper_low:.0f}–{paper_high:.0f} % with `prior_std=\"width\"` (the paper's)."]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reaches", type=int, default=200, help="noisy reaches per preset (default: %(default)s)")
    parser.add_argument("--presets", default="cartesian,planar", help="comma-separated presets (default: %(default)s)")
    parser.add_argument("--markdown", action="store_true", help="print the results page's block instead")
    parser.add_argument("--belief", choices=["robot"], help="only item 2: the sync robot's belief")
    parser.add_argument("--seed", type=int, default=0, help="sampling seed of item 2 (default: %(default)s)")
    args = parser.parse_args()
    robot = robot_belief_calibration(args.reaches, args.seed)
    if args.belief:
        print(robot_table(robot, args.reaches, args.seed), end="")
        return
    results = {preset: calibration(preset, args.reaches) for preset in args.presets.split(",")}
    exact = exact_observation()
    if args.markdown:
        print(markdown_block(results, exact, args.reaches) + "\n" + robot_table(robot, args.reaches, args.seed), end="")
        return
    print("| preset | " + " | ".join(f"{t:g} s: coverage, median error" for t in CHECK_TIMES) + " |")
    print("|---|" + "---|" * len(CHECK_TIMES))
    for preset, result in results.items():
        print(f"| {preset} | " + " | ".join(f"{100 * c:.1f} %, {1e3 * e:.0f} mm" for c, e in result.values()) + " |")
    print()
    print(robot_table(robot, args.reaches, args.seed))
    for key, (low, high) in exact.items():
        print(f"exact observation at 0.165 s, {key}: error {low:.3f}–{high:.3f} % of the distance")


if __name__ == "__main__":
    main()
