"""A progress line for fits: one tick per objective evaluation, with the best value so far."""

from __future__ import annotations

import numpy as np
from tqdm import tqdm


class ProgressBar(tqdm):
    """tqdm over objective evaluations (no total: the optimiser decides when to stop). When stderr is not a
    terminal tqdm still redraws one line; ``enabled=False`` silences it."""

    def __init__(self, description: str, enabled: bool):
        super().__init__(desc=description, unit="evaluation", disable=not enabled, mininterval=0.5)
        self.best = np.inf

    def record(self, value: float) -> None:
        """Count one evaluation whose objective was ``value``."""
        self.best = min(self.best, value)
        self.set_postfix_str(f"best {self.best:.6g}", refresh=False)
        self.update()
