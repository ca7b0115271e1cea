"""Franka reaches with and without the speed cost (model options ``stop_weight``, ``joint_velocity_weight``),
on the same goals in the same run: how the arm ends, how long it whips after the hand stops, and solve times.

    .venv/bin/python benchmarks/franka_rest.py [--goals 8] [--presets franka,franka_rest] [--weights 1,0.02 ...]

Goals: ``--goals`` points 0.15–0.3 m from the ready pose's hand in uniformly drawn directions (seed 0). For each
goal and model: one cold solve (the multi-start guesses) from rest at the ready pose, then one warm solve to a
goal moved by up to 5 cm per axis, warm-started from the cold plan. The models take turns goal by goal, so the
machine's load falls on every row alike. ``--weights s,v`` adds the ``franka`` preset
with stop_weight s and joint_velocity_weight v (one more row per pair).

Per model: successes; the largest final joint speed max_j |qdot_H,j| (rad/s) over the goals and how many plans
end below 0.05 rad/s; the time after MT with a joint at ≥ 95 % of its speed limit (s, largest over the goals);
the medians of cold and warm solve times (ms) and iterations; the medians over the cold plans of MT (s) and of
the paper's objective J (reward and effort, the speed cost left out) over |J_best| (lower is better).
"""

from __future__ import annotations

import argparse

import numpy as np

import comanip
from comanip.analysis import settling_motion, speed_metrics
from comanip.objectives import velocity_cost

REST_SPEED = 0.05
"""rad/s: the issue's bound on every joint's final speed."""


def goal_offsets(count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` offsets (count, 3), m: uniform directions, distances uniform in 0.15–0.3 m."""
    directions = rng.normal(size=(count, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return directions * rng.uniform(0.15, 0.3, size=(count, 1))


def solve_pair(planner: comanip.Planner, origin: np.ndarray, offset: np.ndarray, shift: np.ndarray):
    """(cold plan to origin + offset, warm plan to origin + offset + shift from it), from rest at the ready pose."""
    model = planner.model
    start = np.r_[model.body.home_position, np.zeros(model.n)]
    cold = planner.solve(start, origin + offset)
    return cold, planner.solve(start, origin + offset + shift, warm_start=cold)


def summarise(planner: comanip.Planner, pairs: list) -> dict:
    """The row's numbers from one model's (cold, warm) plans."""
    model = planner.model
    plans = [plan for pair in pairs for plan in pair]
    motions = [settling_motion(model, plan) for plan in plans]
    colds = [cold for cold, _ in pairs]
    warms = [warm for _, warm in pairs]
    return {
        "ok": sum(p.success for p in plans), "plans": len(plans),
        "final_speed_max": max(m.final_joint_speed for m in motions),
        "at_rest": sum(m.final_joint_speed < REST_SPEED for m in motions),
        "limit_time_max": max(m.time_at_velocity_limit for m in motions),
        "cold_ms": 1e3 * np.median([c.solve_time for c in colds]),
        "warm_ms": 1e3 * np.median([w.solve_time for w in warms]),
        "cold_iterations": np.median([c.iterations for c in colds]),
        "warm_iterations": np.median([w.iterations for w in warms]),
        "objective": np.median([paper_objective(model, planner, c) for c in colds]),
        "mt": np.median([speed_metrics(c.t, c.ee_speed).movement_time for c in colds]),
    }


def paper_objective(model: comanip.ReachingModel, planner: comanip.Planner, plan: comanip.Plan) -> float:
    """The SPEC §4 J of the plan without the model's speed cost, over |J_best|: the paper's objective."""
    n, scale = model.n, planner.problem.normaliser(plan.width)
    speed = velocity_cost(plan.mean[1:, n:2 * n], plan.cov[1:, n:2 * n, n:2 * n], model.stop_weight,
                          model.joint_velocity_weight)
    return plan.objective / scale - speed


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--goals", type=int, default=8)
    parser.add_argument("--presets", default="franka,franka_rest")
    parser.add_argument("--weights", nargs="*", default=[], help="stop_weight,joint_velocity_weight pairs")
    args = parser.parse_args(argv)
    offsets = goal_offsets(args.goals, np.random.default_rng(0))
    models = [comanip.presets.load(name) for name in args.presets.split(",") if name]
    for pair in args.weights:
        stop, running = (float(v) for v in pair.split(","))
        models.append(comanip.presets.load("franka").replace(stop_weight=stop, joint_velocity_weight=running,
                                                             name=f"franka s={stop:g} v={running:g}"))
    print(f"| model | stop_weight | joint_velocity_weight | ok | max final joint speed (rad/s) | plans at rest "
          f"(< {REST_SPEED}) | max time at a speed limit after MT (s) | cold ms | warm ms | cold iterations "
          f"| warm iterations | median MT (s) | median paper J/\\|J_best\\| |")
    print("|---" * 13 + "|")
    planners = [comanip.Planner(model) for model in models]
    home = models[0].body.home_position
    origin = np.asarray(models[0].body.kinematics_function(home)[0]).ravel()
    shifts = np.random.default_rng(1).uniform(-0.05, 0.05, size=offsets.shape)
    # goal by goal, every model in turn: the machine's load falls on all rows alike
    pairs = [[solve_pair(planner, origin, offset, shift) for planner in planners] for offset, shift in zip(offsets, shifts)]
    for k, (model, planner) in enumerate(zip(models, planners)):
        r = summarise(planner, [row[k] for row in pairs])
        print(f"| {model.name} | {model.stop_weight:g} | {model.joint_velocity_weight:g} | {r['ok']}/{r['plans']} "
              f"| {r['final_speed_max']:.3f} | {r['at_rest']}/{r['plans']} | {r['limit_time_max']:.3f} "
              f"| {r['cold_ms']:.0f} | {r['warm_ms']:.0f} | {r['cold_iterations']:.0f} | {r['warm_iterations']:.0f} "
              f"| {r['mt']:.3f} | {r['objective']:.4f} |", flush=True)


if __name__ == "__main__":
    main()
