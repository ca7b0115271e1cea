"""The human-likeness section of a validation run: the run's model scored on the targets
(:mod:`comanip.analysis.human_targets`) beside a reference preset (the paper's ``planar`` by default), and the
section's report dictionary (rendered by :func:`comanip.validation.markdown.human_targets_markdown`); its figure is
drawn by :mod:`comanip.plots.validation_figures`.

The run's model is scored on the open-loop grid the run already planned (what a robot predicts) and, when the
model has an ``observation`` (feedback), on its closed-loop executions (what the person does); the reference's
grid is planned here (over the same distances and widths) unless the reference is the run's model itself.
"""

from __future__ import annotations

from dataclasses import asdict

from comanip.analysis.closed_loop_targets import measure_closed_loop_targets
from comanip.analysis.human_targets import HumanTargetsResult, measure_human_targets
from comanip.analysis.reach_grid import ReachOutcome
from comanip.analysis.target_verdicts import HumanTargets
from comanip.model import ReachingModel
from comanip.progress import progress_bar
from comanip.validation.run_settings import ValidationSettings

DEFINITION = "w is the goal radius: a reach hits when ‖x − g‖ ≤ w at MT (2w is the full width), and ID = log2(2D/w) bits"
"""The one definition of w and ID the section states."""


def run_human_section(model: ReachingModel, reference: ReachingModel, grid: list[ReachOutcome],
                      settings: ValidationSettings, progress: bool = True) -> tuple[dict, list[HumanTargetsResult]]:
    """Score model on grid (its open-loop outcomes over settings.distances × settings.widths, with plans)
    and reference. Returns the section's report dictionary and the scored models (what its figure shows)."""
    same = reference.config() == model.config()
    grid_options = {"seed": settings.seed, "distances": settings.distances, "widths": settings.widths}
    feedback = bool(model.observation)
    with progress_bar("human-likeness targets", len(grid) * (1 + (0 if same else 2) + feedback), "condition", progress) as bar:
        results = [measure_human_targets(model, grid, n_samples=settings.human_samples, progress=bar.update, **grid_options)]
        if feedback:
            results.append(measure_closed_loop_targets(model, settings.human_trials, progress=bar.update, **grid_options))
        if not same:
            results.append(measure_human_targets(reference, n_samples=settings.human_samples, progress=bar.update,
                                                 **grid_options))
    return human_section(results), results


def human_section(results: list[HumanTargetsResult], targets: HumanTargets = HumanTargets()) -> dict:
    """The report dictionary of scored models (the first is the one the report is about)."""
    return {"definition": DEFINITION, "thresholds": asdict(targets), "models": [r.to_dict() for r in results]}
