"""What a validation run's figures show, as computed by the run (no plotting here): the drawing step,
:func:`comanip.plots.validation_figures.draw_validation_figures`, turns it into PNG files."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.analysis.arm_reaches import ArmReach
from comanip.analysis.open_loop_dispersion import EndpointDispersion
from comanip.analysis.fitts import FittsFit
from comanip.analysis.human_targets import HumanTargetsResult
from comanip.analysis.phase import PhaseCurve
from comanip.analysis.reach_grid import ReachOutcome
from comanip.model import ReachingModel


@dataclass
class PointMassFigureData:
    """The Section IV-D analyses and the calibration study of one point-mass model."""

    model_name: str
    grid: list[ReachOutcome]
    """Open-loop outcomes (with plans) over the distances × widths grid."""
    fits: list[FittsFit]
    """The Fitts and the Shannon fit of the grid, in that order."""
    profile_distance: float
    profile_width: float
    dispersions: list[EndpointDispersion]
    dispersion_goal: np.ndarray
    by_distance: list[PhaseCurve]
    by_velocity: list[PhaseCurve]
    calibration_rows: list[dict]
    id_range: tuple[float, float]
    """(min, max) Fitts index of difficulty (bits) over the grid."""
    n_distances: int
    n_widths: int


@dataclass
class ArmFigureData:
    """The Franka section: the planned reaches of one arm model."""

    model: ReachingModel
    reaches: list[ArmReach]


@dataclass
class ValidationFigureData:
    """Everything a validation run draws; a section that did not run is None."""

    point_mass: PointMassFigureData | None = None
    human_targets: list[HumanTargetsResult] | None = None
    """The scored models (the first is the one the run is about)."""
    arm: ArmFigureData | None = None
