"""What ``comanip validate`` measures: the grids of the paper's Section IV-D, the calibration study, the
human-likeness targets and the Franka section (Section V-B)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from comanip.arguments import as_count

FRANKA_GOAL_OFFSETS = ((0.2, 0.0, 0.0), (0.0, 0.2, 0.0), (0.0, 0.0, -0.15),
                       (-0.15, 0.0, 0.0), (0.0, -0.2, 0.0), (0.0, 0.0, 0.15))
"""Goals of the Franka section: offsets (m) from the ready pose's end effector (about [0.307, 0, 0.487] m in the base
frame, x forward, z up), 0.15–0.2 m along each axis both ways, all within reach. Ordered so that the first three (the
quick run's) already go forward, sideways and down."""


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
    human_targets: bool = True
    """Score a point-mass model on the human-likeness targets over the distances × widths grid, beside
    human_reference (:mod:`comanip.validation.human_section`)."""
    human_reference: str = "planar"
    """Preset name or YAML path of the model shown beside the run's model in that section."""
    human_samples: int = 2000
    """Open-loop Monte Carlo executions per condition for the targets' hit rate and endpoint SD."""
    human_trials: int = 20
    """Closed-loop executions per condition when the model has an ``observation`` (feedback): its closed loop
    is scored on the targets too (:mod:`comanip.analysis.closed_loop_targets`)."""
    franka: bool = True
    """Run the Franka section: Panda reaches from the ready pose. A point-mass model's run plans with the
    built-in ``franka`` preset; an arm model's run is this section alone."""
    franka_goal_offsets: tuple[tuple[float, ...], ...] = FRANKA_GOAL_OFFSETS
    """Goals of the Franka section as offsets from the ready pose's end-effector position (m, base frame);
    the first is solved cold, each later one warm-started from the plan before it."""
    franka_width: float | None = None
    """Goal width of the Franka reaches (m); the arm model's own (0.05 m for the preset) when None."""
    franka_max_wall_time: float = 60.0
    """Wall-time budget per Franka solve (s); a solve that runs out reports status 'max_wall_time'."""

    def __post_init__(self):
        for name in ("distances", "widths", "dispersion_widths", "phase_distances"):
            values = getattr(self, name)
            if len(values) == 0 or not all(isinstance(v, (int, float)) and math.isfinite(v) and v > 0 for v in values):
                raise ValueError(f"{name} must be a non-empty sequence of finite numbers > 0 (m), got {values!r}")
        positive = [(name, "m") for name in ("profile_distance", "profile_width", "dispersion_distance", "phase_width")]
        positive += [("franka_max_wall_time", "s")] + ([("franka_width", "m")] if self.franka_width is not None else [])
        for name, unit in positive:
            value = getattr(self, name)
            if isinstance(value, bool) or not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0 ({unit}), got {value!r}")
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in self.phase_initial_velocities):
            raise ValueError(f"phase_initial_velocities must be finite numbers (m/s), got {self.phase_initial_velocities!r}")
        for name, least in (("dispersion_samples", 2), ("calibration_trials", 1), ("seed", 0), ("human_samples", 2),
                            ("human_trials", 2)):
            as_count(name, getattr(self, name), least)
        for name in ("franka", "human_targets"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if not isinstance(self.human_reference, str) or not self.human_reference:
            raise ValueError(f"human_reference must be a preset name or a YAML path, got {self.human_reference!r}")
        offsets = self.franka_goal_offsets
        if len(offsets) == 0 or not all(len(o) == 3 and all(isinstance(v, (int, float)) and math.isfinite(v) for v in o)
                                        for o in offsets):
            raise ValueError("franka_goal_offsets must be a non-empty sequence of (x, y, z) offsets of finite numbers (m), "
                             f"got {offsets!r}")
        as_count("workers", self.workers, 1, "processes", optional=True)

    @classmethod
    def quick_run(cls, **changes) -> "ValidationSettings":
        """The ``--quick`` settings: the same grids, fewer samples and configurations, three Franka goals."""
        return cls(**({"dispersion_samples": 500, "calibration_trials": 2, "quick": True, "human_trials": 6,
                       "franka_goal_offsets": FRANKA_GOAL_OFFSETS[:3]} | changes))

    def to_dict(self) -> dict:
        return asdict(self)
