"""What noisy, delayed feedback costs a closed-loop reach (docs/guide/human_like.md, "Feedback from noisy, delayed observation").

Closed-loop reaches of the planar preset (D = 0.3 m along x, w = 0.02 m, 60 steps, replanning every step),
once from the exact state and once from the Kalman estimate made with noisy, delayed observation
(Observation(0.005, 0.05, 0.1)), one run per seed. Prints, per loop: the final hand error (median, max),
the RMS error of the estimated hand position (per run over its steps, then averaged over runs) and the
wall time of a reach (median; depends on the machine's load).

    PYTHONPATH=src python -m studies.what_does_noisy_delayed_feedback_cost.measure_feedback [--seeds 10] [--markdown]

``--markdown`` prints the block ``feedback-cost`` of docs/results/calibration.md instead.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import comanip
from comanip.execution import Observation, execute_receding_horizon

GOAL = np.array([0.3, 0.0])
WIDTH = 0.02
STEPS = 60
VISION = Observation(position_std=0.005, velocity_std=0.05, delay=0.1)


def measure(planner: comanip.Planner, observation: Observation | None, seeds: int) -> dict:
    final_errors, estimate_rms, wall = [], [], []
    n = planner.model.n
    for seed in range(seeds):
        began = time.perf_counter()
        run = execute_receding_horizon(planner, np.zeros(2 * n), GOAL, WIDTH, steps=STEPS,
                                       rng=np.random.default_rng(seed), observation=observation)
        wall.append(time.perf_counter() - began)
        final_errors.append(float(np.linalg.norm(run.ee[-1] - GOAL)))
        if run.estimates is not None:   # point mass: the hand is q, the first n entries of the state
            offsets = run.estimates[:, :n] - run.states[:, :n]
            estimate_rms.append(float(np.sqrt(np.mean(np.sum(offsets**2, axis=1)))))
    return {"final_error_median_mm": 1e3 * np.median(final_errors), "final_error_max_mm": 1e3 * np.max(final_errors),
            "estimate_rms_mm": 1e3 * np.mean(estimate_rms) if estimate_rms else None,
            "reach_wall_time_median_s": float(np.median(wall))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=10, help="runs per loop, seeds 0..N-1 (default: %(default)s)")
    parser.add_argument("--markdown", action="store_true", help="print the results page's block instead")
    args = parser.parse_args()
    planner = comanip.Planner(comanip.presets.planar())
    results = {label: measure(planner, observation, args.seeds) for label, observation in
               (("exact state", None), ("vision", VISION))}
    if args.markdown:
        print(f"Measured by `studies/what_does_noisy_delayed_feedback_cost/measure_feedback.py --seeds {args.seeds}` "
              f"(planar preset, D = {GOAL[0]} m, w = {WIDTH} m, {STEPS} steps replanned every step, seeds "
              f"0–{args.seeds - 1}; vision: {VISION.position_std * 1000:g} mm / {VISION.velocity_std:g} m/s noise, "
              f"{VISION.delay:g} s late).\n")
        print("| loop | final error, median (mm) | final error, max (mm) | estimated hand, RMS error (mm) | wall time of a reach, median (s) |")
        print("|---|---|---|---|---|")
        for label, result in results.items():
            rms = "–" if result["estimate_rms_mm"] is None else f"{result['estimate_rms_mm']:.1f}"
            print(f"| {label} | {result['final_error_median_mm']:.2g} | {result['final_error_max_mm']:.2g} | {rms} | "
                  f"{result['reach_wall_time_median_s']:.2f} |")
        return
    for label, result in results.items():
        rms = "" if result["estimate_rms_mm"] is None else f", estimated hand off by {result['estimate_rms_mm']:.1f} mm RMS"
        print(f"{label}: final error {result['final_error_median_mm']:.2g} mm median, {result['final_error_max_mm']:.2g} mm max"
              f"{rms}; a reach takes {result['reach_wall_time_median_s']:.2f} s (median)")


if __name__ == "__main__":
    main()
