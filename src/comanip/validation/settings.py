"""What ``comanip validate`` measures: the grids of the paper's Section IV-D and the calibration study."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class ValidationSettings:
    """Grids and sample counts of a validation run. Distances and widths in m, velocities in m/s."""

    distances: tuple[float, ...] = (0.15, 0.3, 0.45)
    """Start-to-goal distances D of the Fitts grid (m)."""
    widths: tuple[float, ...] = (0.005, 0.01, 0.02, 0.04)
    """Goal widths w of the Fitts grid (m)."""
    profile_distance: float = 0.3
    """Distance whose profiles across widths the velocity figure shows (m); the paper's goal [0.3, 0]."""
    profile_width: float = 0.02
    """Width whose profiles across distances the velocity figure shows (m)."""
    dispersion_distance: float = 0.45
    """Goal distance of the dispersion study (m); the paper's Fig. 4 goal [0.45, 0]."""
    dispersion_widths: tuple[float, ...] = (0.02, 0.04)
    """Widths of the dispersion study (m), as in the paper's Fig. 4."""
    dispersion_samples: int = 2000
    """Open-loop Monte Carlo executions per dispersion width."""
    phase_distances: tuple[float, ...] = (0.1, 0.2, 0.3, 0.45)
    """Goal distances of the phase plot (m), from rest."""
    phase_initial_velocities: tuple[float, ...] = (-0.3, 0.0, 0.3, 0.6)
    """Initial hand velocities along the reach of the phase plot (m/s), towards a goal at profile_distance."""
    phase_width: float = 0.02
    """Goal width of the phase plots (m)."""
    calibration_trials: int = 6
    """Closed-loop executions averaged per condition in the calibration study."""
    quick: bool = False
    """Reduced calibration (one change at a time, see :func:`comanip.analysis.study_configurations`)."""
    workers: int | None = None
    """Processes for the calibration study (default: the CPU count)."""
    seed: int = 0
    """Seed of every random draw (Monte Carlo and closed-loop noise)."""

    def __post_init__(self):
        for name in ("distances", "widths", "dispersion_widths", "phase_distances"):
            values = getattr(self, name)
            if len(values) == 0 or not all(isinstance(v, (int, float)) and math.isfinite(v) and v > 0 for v in values):
                raise ValueError(f"{name} must be a non-empty sequence of finite numbers > 0 (m), got {values!r}")
        for name in ("profile_distance", "profile_width", "dispersion_distance", "phase_width"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0 (m), got {value!r}")
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in self.phase_initial_velocities):
            raise ValueError(f"phase_initial_velocities must be finite numbers (m/s), got {self.phase_initial_velocities!r}")
        for name, least in (("dispersion_samples", 2), ("calibration_trials", 1), ("seed", 0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < least:
                raise ValueError(f"{name} must be an integer ≥ {least}, got {value!r}")
        if self.workers is not None and (isinstance(self.workers, bool) or not isinstance(self.workers, int) or self.workers < 1):
            raise ValueError(f"workers must be an integer ≥ 1 (processes) or None (the CPU count), got {self.workers!r}")

    @classmethod
    def quick_run(cls, **changes) -> "ValidationSettings":
        """The ``--quick`` settings: the same grids, fewer samples and configurations."""
        return cls(**({"dispersion_samples": 500, "calibration_trials": 2, "quick": True} | changes))

    def to_dict(self) -> dict:
        return asdict(self)
