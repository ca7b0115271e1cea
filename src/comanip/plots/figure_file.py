"""Saving a finished figure: one place for the title size, layout, resolution and closing."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt


def save_figure(fig: plt.Figure, path: str | Path, title: str = "") -> Path:
    """Give fig a title (when not empty), lay it out, write it as a PNG at path and close it; returns the path."""
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
