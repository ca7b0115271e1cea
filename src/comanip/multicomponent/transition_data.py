"""Transition-point data from a simulated person who reaches in two components.

The person is the closed-loop reacher of :func:`comanip.execution.execute_receding_horizon`: at every step
it replans the whole H-step reach from its current noisy state (visual feedback) and executes the first
torque with signal-dependent noise (docs/formulation.md §2). The fast first part of the reach spreads the hand across the
path; the replanning then corrects it, so the perpendicular dispersion rises and falls, and its peak marks
the transition (Peternel & Babič 2019; docs/formulation.md §8).

The person is any point-mass model (default the planar preset; with activation stages the state
[q; qdot; a_1..a_m] starts at rest with zero force). A condition is a goal at distance D = (D/L)·L along x
from rest at the origin, with width w (m). N trials per condition give one row of the transition CSV
(:mod:`comanip.multicomponent.transition_csv`). The sweep runs conditions in parallel on a Dask
``LocalCluster`` (one single-threaded worker process per core; each builds its planner once), with a tqdm
progress bar.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from tqdm import tqdm

from comanip import presets
from comanip.arguments import as_count, as_positive, as_positive_array
from comanip.execution import execute_receding_horizon
from comanip.model import ReachingModel
from comanip.multicomponent.perpendicular_dispersion import bootstrap_transition_std, first_passage_deviations, profile_from_deviations
from comanip.planning.planner import Planner
from comanip.progress import progress_bar

ARM_LENGTH = 0.7
"""Default arm length L (m) that normalises the goal distance."""

SETTLED_SPEED_FRACTION = 0.05
"""Settling criterion (docs/formulation.md §6): final speed below this fraction of the trial's peak speed."""


def default_steps(model: ReachingModel) -> int:
    """Executed steps per reach: 2H. The receding window stays H long, so a person executes more steps than
    H to finish slow, narrow-goal reaches (30 steps left w = 0.005 m reaches unsettled, docs/formulation.md §9)."""
    return 2 * model.H


def simulate_paths(planner: Planner, distance: float, width: float, n_trials: int, steps: int,
                   rng: np.random.Generator) -> tuple[np.ndarray, int, int]:
    """Hand paths of n_trials closed-loop reaches from rest at the origin (the full state (nx,) at zero) to a
    goal distance (m) along x.

    Returns (paths (n_trials, steps+1, d) m, trials that settled in the goal, failed replans in total).
    """
    model = planner.model
    goal = np.zeros(model.d)
    goal[0] = distance
    start = np.zeros(model.state_size)
    paths, settled, failed = [], 0, 0
    for _ in range(n_trials):
        run = execute_receding_horizon(planner, start, goal, width, steps=steps, rng=rng)
        paths.append(run.ee)
        speed = run.ee_speed
        settled += bool(np.linalg.norm(run.ee[-1] - goal) <= width and speed[-1] <= SETTLED_SPEED_FRACTION * speed.max())
        failed += run.failed_replans
    return np.array(paths), settled, failed


def simulate_condition(planner: Planner, distance_over_arm_length: float, width: float, n_trials: int,
                       arm_length: float, steps: int, rng: np.random.Generator) -> dict:
    """One transition-CSV row (dict keyed by the CSV columns) from n_trials reaches of one condition."""
    distance = distance_over_arm_length * arm_length
    paths, settled, failed = simulate_paths(planner, distance, width, n_trials, steps, rng)
    goal = np.zeros(planner.model.d)
    goal[0] = distance
    grid, deviations = first_passage_deviations(paths, goal)
    profile = profile_from_deviations(grid, deviations)
    return {
        "distance_over_arm_length": distance_over_arm_length,
        "width_m": width,
        "transition_distance_m": profile.transition_distance,
        "peak_dispersion_m": profile.peak_dispersion,
        "n_trials": n_trials,
        "transition_distance_se_m": bootstrap_transition_std(grid, deviations, rng),
        "settled_trials": settled,
        "failed_replans": failed,
    }


class TransitionSweep(NamedTuple):
    """The validated inputs of :func:`generate_transition_data` (see its arguments)."""

    distances: np.ndarray
    """D/L (R,), dimensionless."""
    widths: np.ndarray
    """w (K,), m."""
    n_trials: int
    model: ReachingModel
    arm_length: float
    """L, m."""
    steps: int
    seed: int
    workers: int


def checked_sweep(distances_over_arm_length, widths, n_trials: int, *, model: ReachingModel | None, arm_length: float,
                  steps: int | None, seed: int, workers: int) -> TransitionSweep:
    """The inputs of :func:`generate_transition_data` validated before any work (ValueError naming the argument)."""
    model = presets.planar() if model is None else model
    if not isinstance(model, ReachingModel):
        raise ValueError(f"model must be a comanip.ReachingModel, got {type(model).__name__}")
    if not model.body.is_linear:
        raise ValueError(f"model must be a point-mass model (the person starts at rest at the origin and reaches along x), "
                         f"got {model.name!r}, an arm ({model.body.name})")
    distances = np.ravel(as_positive_array("distances_over_arm_length", distances_over_arm_length, "D/L"))
    widths = np.ravel(as_positive_array("widths", widths, "goal width, m"))
    if distances.size == 0 or widths.size == 0:
        raise ValueError(f"distances_over_arm_length and widths must not be empty, got {distances.size} and {widths.size} values")
    arm_length = as_positive("arm_length", arm_length, "m")
    n_trials = as_count("n_trials", n_trials, 3)
    steps = default_steps(model) if steps is None else as_count("steps", steps, 1)
    workers = as_count("workers", workers, 1)
    seed = as_count("seed", seed, 0)
    return TransitionSweep(distances, widths, n_trials, model, arm_length, steps, seed, workers)


def generate_transition_data(distances_over_arm_length, widths, n_trials: int = 40, *,
                             model: ReachingModel | None = None, arm_length: float = ARM_LENGTH,
                             steps: int | None = None, seed: int = 0, workers: int = 2,
                             progress: bool = True) -> list[dict]:
    """Sweep every (D/L, w) pair and return one transition-CSV row per condition, in grid order.

    Args:
        distances_over_arm_length: goal distances D/L (> 0), dimensionless.
        widths: goal widths w (> 0), m.
        n_trials: closed-loop reaches per condition (≥ 3).
        model: the person, any point-mass model (default ``presets.planar()``, a 2-D point mass), reaching along x.
        arm_length: L (m) that turns D/L into metres.
        steps: executed steps per reach (default :func:`default_steps`, 2H).
        seed: seeds every condition's generator (one child of ``SeedSequence(seed)`` per condition, so the
            result does not depend on the number of workers or their order).
        workers: worker processes (1 runs in this process, no Dask). Workers start new Python processes, so
            a script that calls this with workers > 1 needs the ``if __name__ == "__main__":`` guard.
        progress: show a tqdm bar over conditions.
    """
    distances, widths, n_trials, model, arm_length, steps, seed, workers = checked_sweep(
        distances_over_arm_length, widths, n_trials, model=model, arm_length=arm_length, steps=steps, seed=seed, workers=workers)

    conditions = [(float(r), float(w)) for r in distances for w in widths]
    seeds = np.random.SeedSequence(seed).spawn(len(conditions))
    config = model.config()
    tasks = [(config, r, w, n_trials, arm_length, steps, s) for (r, w), s in zip(conditions, seeds)]
    bar = progress_bar("transition conditions", len(tasks), "condition", progress)
    if workers == 1:
        planner = Planner(ReachingModel.from_config(config))
        rows = []
        for _, r, w, *rest in tasks:
            rows.append(_simulate_seeded(planner, r, w, *rest))
            bar.update()
    else:
        rows = _run_on_local_cluster(tasks, workers, bar)
    bar.close()
    return rows


def _run_on_local_cluster(tasks: list[tuple], workers: int, bar: tqdm) -> list[dict]:
    """Run condition tasks on a Dask LocalCluster of single-threaded worker processes; rows in task order."""
    from comanip.caching.worker_cache import WorkerCache
    from comanip.extras import require

    distributed = require("dask.distributed", "sweeps")

    # processes, not threads: CasADi/IPOPT solves hold the GIL; no dashboard (no web server in a batch job)
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        client.register_plugin(WorkerCache(_PLANNERS, Planner, size=2))
        futures = client.map(_condition_task, *zip(*tasks), pure=False)
        index = {future.key: i for i, future in enumerate(futures)}
        rows = [None] * len(tasks)
        for future in distributed.as_completed(futures):
            rows[index[future.key]] = future.result()
            bar.update()
    return rows


_PLANNERS = "comanip-transition-planners"
"""The name of the WorkerCache that gives each Dask worker its planners (:func:`_run_on_local_cluster`)."""


def _condition_task(model_config: dict, distance_over_arm_length: float, width: float, n_trials: int,
                    arm_length: float, steps: int, seed: np.random.SeedSequence) -> dict:
    """One condition on a Dask worker, with the worker's planner for the model (built on its first condition)."""
    from comanip.caching.worker_cache import worker_cache

    return _simulate_seeded(worker_cache(_PLANNERS).get(model_config), distance_over_arm_length, width, n_trials,
                            arm_length, steps, seed)


def _simulate_seeded(planner: Planner, distance_over_arm_length: float, width: float, n_trials: int,
                     arm_length: float, steps: int, seed: np.random.SeedSequence) -> dict:
    return simulate_condition(planner, distance_over_arm_length, width, n_trials, arm_length, steps,
                              np.random.default_rng(seed))
