"""The Franka section of a validation run (paper Section V-B): Panda reaches from the ready pose to goals
around it, their numbers (:mod:`comanip.analysis.arm_reaches`) and CSV files, and what its figures show (drawn by
:mod:`comanip.plots.validation_figures`).

Building the Panda's planner compiles its per-solve functions to C the first time (about a minute, then
cached on disk; :mod:`comanip.caching.compiled`), so the build gets its own progress line.
"""

from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np

from comanip.analysis.arm_reaches import arm_reaches, summarise_reaches
from comanip.model import ReachingModel
from comanip.caching.compiled import cache_dir
from comanip.planning.planner import Planner
from comanip.progress import elapsed, progress_bar
from comanip.validation.figure_data import ArmFigureData
from comanip.validation.run_settings import ValidationSettings

def run_arm_section(model: ReachingModel, out: Path, settings: ValidationSettings,
                    progress: bool = True) -> tuple[dict, ArmFigureData]:
    """Plan the reaches of ``settings.franka_goal_offsets`` with model (an arm), write CSV files into out;
    returns the section's report dictionary and what its figures show."""
    planner, build_time, compiled_now = build_arm_planner(model, progress)
    offsets = np.array(settings.franka_goal_offsets, dtype=float)
    with progress_bar(f"franka: planning reaches ({model.name})", len(offsets), "reach", progress) as bar:
        reaches = arm_reaches(planner, offsets, settings.franka_width, settings.franka_max_wall_time, progress=bar.update)
    body = model.body
    rows = [reach.summary() for reach in reaches]
    _write_csv(rows, out / "franka_reaches.csv")
    plan_folder = out / "franka_plans"
    plan_folder.mkdir(exist_ok=True)
    for k, reach in enumerate(reaches):
        reach.plan.save_csv(plan_folder / f"goal_{k}.csv")
    section = {
        "model": model.config(),
        "home_position_rad": body.home_position.tolist(),
        "home_ee_m": reaches[0].plan.ee_mean[0].tolist(),
        "planner_build_s": build_time,
        "compiled_on_this_run": compiled_now,
        "reaches": rows,
        "summary": summarise_reaches(reaches),
        "files": ["franka_reaches.csv", *(f"franka_plans/goal_{k}.csv" for k in range(len(reaches)))],
    }
    return section, ArmFigureData(model, reaches)


def build_arm_planner(model: ReachingModel, progress: bool = True) -> tuple[Planner, float, bool]:
    """The model's :class:`Planner`, built under a progress line that shows the elapsed time.

    Returns the planner, the build's wall time (s), and whether it compiled new C libraries (first use
    of this model on this machine) rather than loading them from the cache.
    """
    before = _cached_libraries()
    began = time.perf_counter()
    description = f"franka: building the {model.body.name.capitalize()}'s functions (compiled to C on first use, cached after)"
    with elapsed(description, progress):
        planner = Planner(model)
    return planner, time.perf_counter() - began, bool(_cached_libraries() - before)


def _cached_libraries() -> set[Path]:
    folder = cache_dir()
    return set(folder.glob("*.so")) if folder.is_dir() else set()


def _write_csv(rows: list[dict], path: Path) -> None:
    """One row per reach; list-valued fields (offsets, goals, per-joint usage) as one column per entry."""
    flat = []
    for row in rows:
        entries = {}
        for key, value in row.items():
            if isinstance(value, list):
                entries |= {f"{key}_{k + 1}": v for k, v in enumerate(value)}
            else:
                entries[key] = value
        flat.append(entries)
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(flat[0]))
        writer.writeheader()
        writer.writerows(flat)

