"""Check transition data and a fitted transition model against the published trends (docs/formulation.md §8).

Peternel & Babič (2019) measured that a farther goal moves the peak perpendicular dispersion farther from
the goal and makes it larger, and that a larger goal moves it closer to the goal and makes it larger.
How each is checked is :data:`METHOD`.
"""

from __future__ import annotations

import numpy as np
from scipy import stats

from comanip.multicomponent.transition_model import TransitionModel

PUBLISHED_TRENDS = {
    ("distance_over_arm_length", "transition_distance_m"): (+1, "a farther goal moves the peak farther from the goal"),
    ("distance_over_arm_length", "peak_dispersion_m"): (+1, "a farther goal makes the peak dispersion larger"),
    ("width_m", "transition_distance_m"): (-1, "a larger goal moves the peak closer to the goal"),
    ("width_m", "peak_dispersion_m"): (+1, "a larger goal makes the peak dispersion larger"),
}
"""(input column, output column) -> (published sign of the slope, the claim in words)"""

_INPUTS = ("distance_over_arm_length", "width_m")

METHOD = ("Data: ordinary least squares y = a + b_r·(D/L) + b_w·w over the rows; a slope's verdict is 'reproduced' "
          "when its 95 % confidence interval excludes zero on the published side, 'reversed' when it excludes zero on "
          "the other side, 'not significant' otherwise. Model: the change of the GP's mean transition distance across "
          "the data's range of one input, averaged over the other input's range, with its posterior standard "
          "deviation; the same verdicts at ±2 std.")


def trend_report(model: TransitionModel, grid_points: int = 11) -> dict:
    """Each published trend with the data's slope (and CI) and the model's change over the range, with verdicts."""
    data = model.training_data
    trends = []
    for (inp, out), (sign, claim) in PUBLISHED_TRENDS.items():
        entry = {"input": inp, "output": out, "claim": claim, "published_sign": sign}
        entry["data"] = data_trend(data, inp, out, sign) if out in data else None
        entry["model"] = model_trend(model, inp, sign, grid_points) if out == "transition_distance_m" else None
        trends.append(entry)
    return {"source": "Peternel & Babič 2019 (docs/formulation.md §8)", "method": METHOD,
            "rows": int(len(data["width_m"])), "trends": trends}


def data_trend(data: dict, inp: str, out: str, sign: int) -> dict:
    """OLS slope of data[out] on data[inp] (the other input held in the regression), 95 % CI, verdict."""
    X = np.column_stack([np.ones(len(data[out]))] + [data[c] for c in _INPUTS])
    y = data[out]
    coefficients, _, rank, _ = np.linalg.lstsq(X, y, rcond=None)
    dof = len(y) - X.shape[1]
    if rank < X.shape[1] or dof < 1:
        return {"slope": None, "verdict": "undetermined (an input does not vary or too few rows)"}
    residual = y - X @ coefficients
    covariance = (residual @ residual / dof) * np.linalg.inv(X.T @ X)
    k = 1 + _INPUTS.index(inp)
    slope, se = float(coefficients[k]), float(np.sqrt(covariance[k, k]))
    half = float(stats.t.ppf(0.975, dof)) * se
    span = float(np.ptp(data[inp]))
    return {"slope": slope, "slope_ci95": [slope - half, slope + half], "slope_units": f"{_unit(out)} per {_unit(inp)}",
            "change_over_range": slope * span, "change_units": _unit(out),
            "verdict": _verdict(slope, half, sign)}


def model_trend(model: TransitionModel, inp: str, sign: int, grid_points: int = 11) -> dict:
    """Mean change of the predicted transition distance (m) from the low to the high end of inp's data range,
    averaged over grid_points values of the other input, with its posterior std (m) and a verdict at ±2 std."""
    ranges = model.data_range
    other = _INPUTS[1 - _INPUTS.index(inp)]
    others = np.linspace(*ranges[other], grid_points)
    ends = {inp: np.repeat(ranges[inp], grid_points), other: np.tile(others, 2)}
    mean, cov = model.posterior(ends["distance_over_arm_length"], ends["width_m"])
    weights = np.concatenate([-np.ones(grid_points), np.ones(grid_points)]) / grid_points
    change, std = float(weights @ mean), float(np.sqrt(max(weights @ cov @ weights, 0.0)))
    return {"change_over_range": change, "std": std, "units": "m", "range": list(ranges[inp]),
            "verdict": _verdict(change, 2 * std, sign)}


def _verdict(value: float, half_width: float, sign: int) -> str:
    if abs(value) <= half_width:
        return "not significant"
    return "reproduced" if np.sign(value) == sign else "reversed"


def _unit(column: str) -> str:
    return "unit D/L" if column == "distance_over_arm_length" else "m"
