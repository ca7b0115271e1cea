"""The validation run behind ``comanip validate``: analyses and reports in one call.

The run computes what its figures show and draws nothing itself: ``comanip validate`` draws them with
:func:`comanip.plots.validation_figures.draw_validation_figures` (so ``import comanip.validation`` does not load
matplotlib).
"""

from comanip.validation.figure_data import ValidationFigureData
from comanip.validation.run import run_validation
from comanip.validation.run_settings import ValidationSettings

__all__ = ["run_validation", "ValidationFigureData", "ValidationSettings"]
