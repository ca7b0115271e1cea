"""What ``comanip validate`` measures: the grids of the paper's Section IV-D and the calibration study."""

from __future__ import annotations

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

    @classmethod
    def quick_run(cls, **changes) -> "ValidationSettings":
        """The ``--quick`` settings: the same grids, fewer samples and configurations."""
        return cls(**({"dispersion_samples": 500, "calibration_trials": 2, "quick": True} | changes))

    def to_dict(self) -> dict:
        return asdict(self)
