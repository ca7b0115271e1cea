"""A progress line for fits: one tick per objective evaluation, with the best value so far."""

from __future__ import annotations

import numpy as np
from tqdm import tqdm

from comanip.progress import progress_options


class ProgressBar(tqdm):
    """tqdm over objective evaluations (no total: the optimiser decides when to stop), redrawn in a terminal
    and one line per update in a log (:mod:`comanip.progress`); ``enabled=False`` silences it."""

    def __init__(self, description: str, enabled: bool):
        super().__init__(desc=description, unit="evaluation", **progress_options(enabled))
        self.best = np.inf

    def record(self, value: float) -> None:
        """Count one evaluation whose objective was ``value``."""
        self.best = min(self.best, value)
        self.set_postfix_str(f"best {self.best:.6g}", refresh=False)
        self.update()
