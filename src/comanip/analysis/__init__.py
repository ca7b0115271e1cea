"""Validation analyses (paper Section IV-D, Fig. 3–5) and the calibration study: pure functions over plans
and executions that return numbers (dataclasses), which :mod:`comanip.plots` draws and ``comanip validate``
reports."""

from comanip.analysis.arm_reaches import (
    ArmReach,
    LimitUsage,
    SettlingMotion,
    arm_reaches,
    joint_limit_usage,
    settling_motion,
    summarise_reaches,
)
from comanip.analysis.ball_probability import ball_probability
from comanip.analysis.calibration import (
    CalibrationResult,
    Configuration,
    measure_grid,
    run_calibration,
    study_configurations,
)
from comanip.analysis.open_loop_dispersion import EndpointDispersion, endpoint_dispersion
from comanip.analysis.closed_loop_targets import measure_closed_loop_targets
from comanip.analysis.fitts import FITTS_FORMS, FittsFit, fit_fitts, index_of_difficulty, trend_fraction
from comanip.analysis.human_targets import (
    TARGET_DISTANCES,
    TARGET_WIDTHS,
    ConditionTargets,
    HumanTargetsResult,
    condition_targets,
    measure_human_targets,
)
from comanip.analysis.minimum_jerk_baseline import (
    minimum_jerk_asymmetry,
    minimum_jerk_settling_fraction,
    minimum_jerk_speed_fraction,
    minimum_jerk_velocity,
)
from comanip.analysis.phase import PhaseCurve, phase_curves
from comanip.analysis.profile_shape import ProfileShape, profile_shape
from comanip.analysis.reach_grid import ReachOutcome, closed_loop_grid, home_start, open_loop_grid, unit_direction
from comanip.analysis.speed_profile import SETTLING_FRACTION, ReachTiming, SpeedMetrics, movement_timing, speed_metrics
from comanip.analysis.target_verdicts import HumanTargets, TargetVerdict, target_verdicts

__all__ = [
    "ArmReach", "LimitUsage", "SettlingMotion", "arm_reaches", "joint_limit_usage", "settling_motion", "summarise_reaches",
    "ball_probability",
    "CalibrationResult", "Configuration", "measure_grid", "run_calibration", "study_configurations",
    "EndpointDispersion", "endpoint_dispersion",
    "FITTS_FORMS", "FittsFit", "fit_fitts", "index_of_difficulty", "trend_fraction",
    "TARGET_DISTANCES", "TARGET_WIDTHS", "ConditionTargets", "HumanTargetsResult", "condition_targets",
    "measure_human_targets",
    "measure_closed_loop_targets",
    "minimum_jerk_asymmetry", "minimum_jerk_settling_fraction", "minimum_jerk_speed_fraction", "minimum_jerk_velocity",
    "PhaseCurve", "phase_curves",
    "ProfileShape", "profile_shape",
    "ReachOutcome", "closed_loop_grid", "home_start", "open_loop_grid", "unit_direction",
    "SETTLING_FRACTION", "ReachTiming", "SpeedMetrics", "movement_timing", "speed_metrics",
    "HumanTargets", "TargetVerdict", "target_verdicts",
]
