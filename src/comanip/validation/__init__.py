"""The validation run behind ``comanip validate``: analyses, figures and reports in one call.

``import comanip.validation`` loads the settings only; :func:`run_validation`, which draws the figures, is
imported (with matplotlib) on first use.
"""

from comanip.validation.settings import ValidationSettings

__all__ = ["run_validation", "ValidationSettings"]


def __getattr__(name: str):
    if name == "run_validation":
        from comanip.validation.run import run_validation

        return run_validation
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
