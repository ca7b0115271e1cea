"""Human-likeness targets and the verdict of a model's measurements against them.

w is the goal radius everywhere: a reach hits when ||x − g|| ≤ w at the movement time, so 2w is the goal's
full width and the index of difficulty is ID = log2(2D/w) (bits). The targets, on the grid D × w of reaches
from rest:

1. hit rate in the band (0.90–0.99) in every condition, in closed form and by Monte Carlo;
2. MT = a + b·ID with R² ≥ 0.95 and b in 80–160 ms/bit, and the 0.3 m / 0.01 m reach taking 0.5–1.0 s;
3. t_peak/MT ≤ 0.5 in every condition and not rising with ID (least-squares slope ≤ 0);
4. the speed profile: 50 ms after the start below 15 % of the peak, one peak (local maxima of at least 10 %
   of the peak), no reversal (along-path velocity never below −1 % of the peak speed), and below 5 % of
   the peak at the end of the horizon;
5. the endpoint SD (closed form, along and across the reach) growing with w at each D, and the peak speed
   1.6–2.2 times D/MT (minimum jerk: 1.76).

Every plan must also have converged and settled (finite MT); that check is listed with the targets.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Callable

import numpy as np

from comanip.analysis.fitts import FittsFit


@dataclass(frozen=True)
class ConditionTargets:
    """Every number of one condition the targets use. Lengths in m, times in s, ratios dimensionless."""

    distance: float
    width: float
    """Goal radius w."""
    index_of_difficulty: float
    """log2(2D/w), bits."""
    movement_time: float
    """docs/formulation.md §6 MT (NaN when the reach never settles)."""
    t_peak: float
    asymmetry: float
    """t_peak/MT."""
    peak_speed: float
    """m/s."""
    peak_speed_ratio: float
    """Peak speed / (D/MT)."""
    onset: float
    """Speed at the targets' onset time over the peak speed."""
    onset_minimum_jerk: float
    """The same for the minimum-jerk reach with this MT (a reference: small only for slow reaches)."""
    peaks: int
    reversal: float
    """Most negative along-path velocity over the peak speed."""
    end_speed: float
    """Speed at the end of the horizon over the peak speed."""
    endpoint_time: float
    """Time of the step at which the hand is scored (s)."""
    hit_rate_closed_form: float
    hit_rate_monte_carlo: float
    sd_along: float
    """Monte Carlo SD of the hand along the reach at endpoint_time (m)."""
    sd_across: float
    """Monte Carlo SD across the reach (m)."""
    sd_along_predicted: float
    """Closed-form SD along the reach (m)."""
    sd_across_predicted: float
    """Closed-form SD across the reach (m)."""
    samples: int
    """Monte Carlo executions."""
    success: bool
    """The plan's solve converged."""

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class HumanTargets:
    """Thresholds of the targets. Ranges are inclusive (low, high)."""

    hit_rate: tuple[float, float] = (0.90, 0.99)
    """P(||x − g|| ≤ w) at MT, every condition."""
    fitts_r2_min: float = 0.95
    """Least R² of MT = a + b·log2(2D/w)."""
    fitts_slope: tuple[float, float] = (80.0, 160.0)
    """Range of the slope b (ms/bit)."""
    reference_condition: tuple[float, float] = (0.3, 0.01)
    """(D, w) in m of the reach whose MT is checked."""
    reference_mt: tuple[float, float] = (0.5, 1.0)
    """Range of that reach's MT (s)."""
    asymmetry_max: float = 0.5
    """Largest t_peak/MT, every condition."""
    asymmetry_slope_max: float = 0.0
    """Largest least-squares slope of t_peak/MT against ID (1/bit)."""
    onset_time: float = 0.05
    """When the onset speed is measured, after the start (s)."""
    onset_max: float = 0.15
    """Speed at onset_time over the peak speed must be below this."""
    peak_floor: float = 0.10
    """Local maxima of the speed below this fraction of the peak do not count as peaks."""
    reversal_min: float = -0.01
    """Most negative along-path velocity over the peak speed must be at least this."""
    end_speed_max: float = 0.05
    """Speed at the end of the horizon over the peak speed must be below this."""
    peak_speed_ratio: tuple[float, float] = (1.6, 2.2)
    """Range of peak speed / (D/MT)."""


@dataclass(frozen=True)
class TargetVerdict:
    """One target: what was measured (range over the conditions, or one number) against its threshold."""

    target: str
    unit: str
    threshold: str
    low: float
    """Smallest measured value (NaN when none is finite); for a single number, the number."""
    high: float
    """Largest measured value; for a single number, the number."""
    passed: bool
    checked: int = 1
    """How many values were checked: conditions, pairs of conditions, or 1 for a single number."""
    failing: tuple[str, ...] = ()
    """Conditions (as 'D/w' in m) or pairs of conditions that miss the target; empty for a single number."""

    def to_dict(self) -> dict:
        return asdict(self) | {"failing": list(self.failing)}


def target_verdicts(rows: list[ConditionTargets], fit: FittsFit, asymmetry_slope: float,
                    targets: HumanTargets = HumanTargets()) -> list[TargetVerdict]:
    """The verdict on every target from the per-condition rows, the Fitts-form fit of their MT and the
    least-squares slope of their t_peak/MT against ID (1/bit)."""
    tg = targets
    hit_low, hit_high = tg.hit_rate
    D_ref, w_ref = tg.reference_condition
    reference = [r.movement_time for r in rows if np.isclose(r.distance, D_ref) and np.isclose(r.width, w_ref)]
    reference_mt = reference[0] if reference else np.nan
    slope_ms = 1e3 * fit.b
    speed_low, speed_high = tg.peak_speed_ratio

    def each(target, unit, threshold, values, ok: Callable[[np.ndarray], np.ndarray]) -> TargetVerdict:
        return _each(rows, target, unit, threshold, values, ok)

    return [
        each("hit rate at MT, closed form", "", f"{hit_low:g}–{hit_high:g} in every condition",
             [r.hit_rate_closed_form for r in rows], lambda v: (v >= hit_low) & (v <= hit_high)),
        each("hit rate at MT, Monte Carlo", "", f"{hit_low:g}–{hit_high:g} in every condition",
             [r.hit_rate_monte_carlo for r in rows], lambda v: (v >= hit_low) & (v <= hit_high)),
        _single("R² of MT = a + b·ID", "", f"≥ {tg.fitts_r2_min:g}", fit.r2, fit.r2 >= tg.fitts_r2_min),
        _single("Fitts slope b", "ms/bit", f"{tg.fitts_slope[0]:g}–{tg.fitts_slope[1]:g}", slope_ms,
                tg.fitts_slope[0] <= slope_ms <= tg.fitts_slope[1]),
        _single(f"MT of the {D_ref:g} m / {w_ref:g} m reach", "s", f"{tg.reference_mt[0]:g}–{tg.reference_mt[1]:g}",
                reference_mt, tg.reference_mt[0] <= reference_mt <= tg.reference_mt[1]),
        each("t_peak/MT", "", f"≤ {tg.asymmetry_max:g} in every condition", [r.asymmetry for r in rows],
             lambda v: v <= tg.asymmetry_max),
        _single("slope of t_peak/MT against ID", "1/bit", f"≤ {tg.asymmetry_slope_max:g}", asymmetry_slope,
                asymmetry_slope <= tg.asymmetry_slope_max),
        each(f"speed {1e3 * tg.onset_time:g} ms after the start / peak", "", f"< {tg.onset_max:g} in every condition",
             [r.onset for r in rows], lambda v: v < tg.onset_max),
        each(f"speed peaks (local maxima ≥ {100 * tg.peak_floor:g} % of the peak)", "", "1 in every condition",
             [r.peaks for r in rows], lambda v: v == 1),
        each("most negative along-path velocity / peak speed", "", f"≥ {tg.reversal_min:g} in every condition",
             [r.reversal for r in rows], lambda v: v >= tg.reversal_min),
        each("speed at the end of the horizon / peak", "", f"< {tg.end_speed_max:g} in every condition",
             [r.end_speed for r in rows], lambda v: v < tg.end_speed_max),
        _sd_growth(rows),
        each("peak speed / (D/MT)", "", f"{speed_low:g}–{speed_high:g} in every condition",
             [r.peak_speed_ratio for r in rows], lambda v: (v >= speed_low) & (v <= speed_high)),
        each("plan converged and settled (finite MT)", "", "every condition",
             [float(r.success and np.isfinite(r.movement_time)) for r in rows], lambda v: v == 1),
    ]


def _each(rows, target: str, unit: str, threshold: str, values, ok) -> TargetVerdict:
    """A per-condition target: values (k,) one per row, ok(values) -> (k,) bool; NaN values fail."""
    values = np.asarray(values, dtype=float)
    good = np.asarray(ok(values), dtype=bool) & np.isfinite(values)
    failing = tuple(_label(r.distance, r.width) for r, g in zip(rows, good) if not g)
    return TargetVerdict(target, unit, threshold, _finite(np.min, values), _finite(np.max, values), not failing,
                         len(values), failing)


def _single(target: str, unit: str, threshold: str, value: float, passed) -> TargetVerdict:
    """A target on one number; a NaN value fails."""
    value = float(value)
    return TargetVerdict(target, unit, threshold, value, value, bool(passed) and bool(np.isfinite(value)))


def _sd_growth(rows: list[ConditionTargets]) -> TargetVerdict:
    """Endpoint SD along and across (closed form) against the next larger width at the same D: every ratio
    SD(w_next)/SD(w) must exceed 1. low/high: the smallest and largest ratio."""
    ratios, failing = [], []
    for distance in sorted({r.distance for r in rows}):
        line = sorted((r for r in rows if r.distance == distance), key=lambda r: r.width)
        for before, after in zip(line, line[1:]):
            pair = [after.sd_along_predicted / before.sd_along_predicted, after.sd_across_predicted / before.sd_across_predicted]
            ratios += pair
            if not all(ratio > 1 for ratio in pair):
                failing.append(f"{_label(distance, before.width)}→{after.width:g}")
    values = np.array(ratios, dtype=float)
    return TargetVerdict("endpoint SD ratio, next larger w at the same D (along and across, closed form)", "",
                         "> 1 for every pair", _finite(np.min, values), _finite(np.max, values),
                         not failing and len(ratios) > 0, len(ratios) // 2, tuple(failing))


def _label(distance: float, width: float) -> str:
    return f"{distance:g}/{width:g}"


def _finite(stat, values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(stat(finite)) if finite.size else float("nan")
