"""Simulation speed: how much faster than real time the default co-manipulation scenarios run.

    .venv/bin/python benchmarks/simulation_speed.py [--trials 5] [--repeats 1] [--only sync,handover]

Each scenario builds its parts once (MuJoCo models, the Cartesian preset's planner, the goal estimator or
the transition model; build time reported apart), then runs `repeats` × `trials` trials to the near and
the far goal. Per trial (2.75 s simulated at 1 kHz): wall time, the share of it spent in the person's
re-plans and in the robot's one-off solve (sync: the goal estimate; handover: the plan, made once per
goal before the trials), and the real-time factor = simulated time / wall time. Rows print medians over
the trials; "excl. robot solve" leaves out the robot's estimate, which a real robot makes while the
world keeps moving, not inside a paused simulation.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from comanip.simulation import HandoverSettings, ScenarioSetup, SyncSettings, run_handover, run_sync


def sync_trials(setup: ScenarioSetup, goal: str, trials: int, seed: int) -> list[tuple[float, float, float]]:
    """(wall, person re-plan, robot solve) seconds per trial."""
    runs = run_sync(SyncSettings(goal=goal, trials=trials, seed=seed), setup, progress=False)
    return [(t.record.wall_time, t.record.replan_time, t.estimate.solve_time) for t in runs]


def handover_trials(setup: ScenarioSetup, goal: str, trials: int, seed: int) -> list[tuple[float, float, float]]:
    run = run_handover(HandoverSettings(goal=goal, trials=trials, seed=seed), setup, progress=False)
    return [(t.record.wall_time, t.record.replan_time, 0.0) for t in run.trials]


CASES = {"sync": (SyncSettings, sync_trials), "handover": (HandoverSettings, handover_trials)}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--trials", type=int, default=5, help="trials per goal and repeat")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--only", default="", help=f"comma-separated scenarios, of: {', '.join(CASES)}")
    args = parser.parse_args(argv)
    wanted = [w for w in args.only.split(",") if w]
    print(f"{'scenario':<10} {'goal':<5} {'build s':>8} {'trials':>6} {'sim s':>6} {'wall s':>7} {'replans s':>9} "
          f"{'robot s':>8} {'x real time':>11} {'excl. robot':>11}")
    for name, (settings_class, run) in CASES.items():
        if wanted and name not in wanted:
            continue
        begin = time.perf_counter()
        setup = ScenarioSetup(settings_class())
        setup.world, setup.planner                             # build before timing
        if name == "sync":
            setup.estimator
        build = time.perf_counter() - begin
        for goal in ("near", "far"):
            rows = np.array([row for repeat in range(args.repeats)
                             for row in run(setup, goal, args.trials, seed=repeat * args.trials)])
            wall, replans, robot = np.median(rows, axis=0)
            simulated = setup.duration
            factor = np.median(simulated / rows[:, 0])
            without_robot = np.median(simulated / (rows[:, 0] - rows[:, 2]))
            print(f"{name:<10} {goal:<5} {build:8.2f} {len(rows):6d} {simulated:6.2f} {wall:7.3f} {replans:9.3f} "
                  f"{robot:8.3f} {factor:10.1f}x {without_robot:10.1f}x", flush=True)
            build = 0.0


if __name__ == "__main__":
    main()
