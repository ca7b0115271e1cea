"""The figures of a validation run, drawn from what the run computed (:mod:`comanip.validation.figure_data`):
the drawing step of ``comanip validate``, kept out of the validation layer."""

from __future__ import annotations

from pathlib import Path

from comanip.plots.arm_figure import plot_arm_paths, plot_arm_speed_profiles, plot_joint_trajectories
from comanip.plots.asymmetry_figure import plot_asymmetry_against_difficulty
from comanip.plots.calibration_figure import plot_calibration
from comanip.plots.dispersion_figure import plot_dispersion
from comanip.plots.fitts_figure import plot_fitts
from comanip.plots.human_targets_figure import plot_human_targets
from comanip.plots.phase_figure import plot_phase
from comanip.plots.velocity_profiles import plot_velocity_profiles
from comanip.validation.figure_data import ArmFigureData, PointMassFigureData, ValidationFigureData

HUMAN_FIGURE = "human_targets.png"
"""Figure file of the human-likeness section."""
ARM_FIGURES = ("franka_speed_profiles.png", "franka_joint_positions.png", "franka_joint_velocities.png", "franka_paths.png")
"""Figure files of the Franka section, in the order the report lists them."""


def draw_validation_figures(data: ValidationFigureData, out: str | Path) -> list[Path]:
    """Draw every figure of the sections in data into out; the paths, in the order the report lists them."""
    out = Path(out)
    figures = []
    if data.point_mass is not None:
        figures += draw_point_mass_figures(data.point_mass, out)
    if data.human_targets is not None:
        figures.append(draw_human_targets_figure(data.human_targets, out))
    if data.arm is not None:
        figures += draw_arm_figures(data.arm, out)
    return figures


def draw_point_mass_figures(data: PointMassFigureData, out: Path) -> list[Path]:
    """Speed profiles, Fitts fits, dispersion, phase plots, calibration and asymmetry figures."""
    name = data.model_name
    return [
        plot_velocity_profiles(data.grid, data.fits[0], data.profile_distance, data.profile_width, out / "velocity_profiles.png",
                               f"{name}: speed profiles (solid), minimum jerk with the same MT (dashed)"),
        plot_fitts(data.grid, data.fits, out / "fitts.png", f"{name}: movement time against index of difficulty (open-loop plans)"),
        plot_dispersion(data.dispersions, data.dispersion_goal, out / "dispersion.png",
                        title=f"{name}: open-loop executions of the planned torques, goal {data.dispersion_goal.round(3).tolist()} m"),
        plot_phase(data.by_distance, data.by_velocity, out / "phase.png", f"{name}: phase plots along the reach (plans)"),
        plot_calibration(data.calibration_rows, out / "calibration.png",
                         f"calibration study on {name}: {data.n_distances} distances × {data.n_widths} widths"),
        plot_asymmetry_against_difficulty(data.calibration_rows, data.id_range, out / "asymmetry_vs_difficulty.png"),
    ]


def draw_human_targets_figure(results, out: Path) -> Path:
    """The human-likeness targets of the scored models."""
    names = " vs ".join(r.model_name for r in results)
    return plot_human_targets(results, out / HUMAN_FIGURE, title=f"human-likeness targets: {names}")


def draw_arm_figures(data: ArmFigureData, out: Path) -> list[Path]:
    """Hand speed, joint positions and velocities against the limits, and hand paths of the arm's reaches."""
    body, name, reaches = data.model.body, data.model.name, data.reaches
    return [
        plot_arm_speed_profiles(reaches, out / ARM_FIGURES[0], f"{name}: hand speed of plans from the ready pose"),
        plot_joint_trajectories(reaches, body.q_min, body.q_max, False, out / ARM_FIGURES[1],
                                f"{name}: joint positions of the plans (dashed: URDF limits)"),
        plot_joint_trajectories(reaches, -body.qdot_max, body.qdot_max, True, out / ARM_FIGURES[2],
                                f"{name}: joint velocities of the plans (dashed: URDF limits)"),
        plot_arm_paths(reaches, out / ARM_FIGURES[3], f"{name}: hand paths from the ready pose (base frame)"),
    ]
