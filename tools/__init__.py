"""Scripts that regenerate the documentation from measurements (``python -m tools.regenerate_results``) and check it
against them, run from the repository root."""
