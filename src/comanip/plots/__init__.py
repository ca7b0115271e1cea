"""Figures (matplotlib, headless Agg backend): one module per kind of figure, each saving a PNG."""

import matplotlib

matplotlib.use("Agg")
