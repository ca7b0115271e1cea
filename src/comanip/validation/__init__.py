"""The validation run behind ``comanip validate``: analyses, figures and reports in one call."""

from comanip.validation.run import run_validation
from comanip.validation.settings import ValidationSettings

__all__ = ["run_validation", "ValidationSettings"]
