"""Fit model parameters to movement times per condition, the way published Fitts studies report them.

A movement-time table is a CSV with one row per condition and the columns ``distance_m`` (D, m),
``width_m`` (w, m) and ``mt_s`` (mean MT, s). Each condition is planned from rest at the body's home
position to a goal D along +x; its predicted MT is :func:`comanip.analysis.speed_metrics`'s (first time
after the speed peak below 5 % of the peak). scipy's ``least_squares`` (trust region, bounded, forward
differences in the transformed parameters) minimises Σ (MT_pred − MT)². A reach that has not settled
within the horizon counts as lasting the whole horizon H·h. Standard errors are the least-squares ones,
s²(JᵀJ)⁻¹ with s² = SSE / (m − p) (m conditions, p parameters): the Laplace approximation of a Gaussian
likelihood of the MTs with unknown variance.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from comanip.arguments import as_count, as_positive, as_positive_array
from comanip.fitting.condition_plans import ConditionPlanner
from comanip.recordings.csv_table import read_table
from comanip.fitting.parameters import MT_DEFAULT_PARAMETERS, ParameterSpace
from comanip.fitting.evaluation_progress import ProgressBar
from comanip.fitting.residuals import movement_time
from comanip.fitting.fit_result import FitResult, FitStatus, failed_result, fitted_model, identification, outcome_message
from comanip.model import ReachingModel

MT_COLUMNS = ("distance_m", "width_m", "mt_s")
SSE_KIND = "sum of squared MT errors (s²)"


@dataclass(frozen=True)
class MovementTimeTable:
    """Movement times of m conditions."""

    distance: np.ndarray
    """Goal distances D (m,), m, > 0."""
    width: np.ndarray
    """Goal widths w (m,), m, > 0."""
    mt: np.ndarray
    """Mean movement times (m,), s, > 0."""

    @classmethod
    def read(cls, path: str | Path) -> "MovementTimeTable":
        """From a CSV with the columns distance_m, width_m, mt_s (other columns are ignored)."""
        table = read_table(path, "movement-time table", MT_COLUMNS, MT_COLUMNS)
        return cls(*(as_positive_array(f"{name} in {str(path)!r}", table[name], "m or s") for name in MT_COLUMNS))


def fit_movement_times(model: ReachingModel, table: str | Path | MovementTimeTable, parameters: Sequence[str] = MT_DEFAULT_PARAMETERS,
                       *, bounds: dict | None = None, max_evaluations: int = 100, diff_step: float = 0.01,
                       scheduler=None, progress: bool = True) -> FitResult:
    """Least-squares fit of model fields to movement times per condition.

    Args:
        model: the model to start from (other fields fixed).
        table: a movement-time CSV (distance_m, width_m, mt_s) or a :class:`MovementTimeTable`.
        parameters: free model fields (as in :func:`comanip.fitting.fit_model`; 'sigma_obs' has no meaning here).
        bounds: {name: (low, high)} natural-unit bounds (default: a factor 1000 around the start).
        max_evaluations: evaluation budget of ``least_squares`` (finite-difference evaluations not counted).
        diff_step: relative finite-difference step in the transformed parameters.
        scheduler: None, a Dask scheduler address or a Client (as in ``fit_model``).
        progress: show a tqdm line.

    Returns:
        A :class:`FitResult` whose objective is the sum of squared MT errors (s²) and whose conditions list
        D, w, the given and the predicted MT; status 'failed' (never an exception) when the fit breaks down.
    """
    table = table if isinstance(table, MovementTimeTable) else MovementTimeTable.read(table)
    if not isinstance(model, ReachingModel):
        raise ValueError(f"model must be a comanip.ReachingModel, got {type(model).__name__}")
    if "sigma_obs" in parameters:
        raise ValueError("sigma_obs is the recordings' measurement noise; a movement-time fit has no use for it")
    space = ParameterSpace(model, parameters, bounds=bounds)
    max_evaluations = as_count("max_evaluations", max_evaluations)
    diff_step = as_positive("diff_step", diff_step, "relative step")
    start = np.concatenate([model.body.home_position, np.zeros(model.n)])
    home = np.asarray(model.body.kinematics_function(model.body.home_position)[0]).ravel()
    reaches = [(start, home + D * np.eye(model.d)[0], w) for D, w in zip(table.distance, table.width)]
    t_begin = time.perf_counter()
    with ConditionPlanner(reaches, scheduler) as planner, ProgressBar("fit movement times", progress) as bar:
        residuals = _MovementTimeResiduals(space, planner, table.mt, bar.record)
        try:
            low, high = np.array(space.bounds).T
            result = least_squares(residuals, space.initial, bounds=(low, high), method="trf", diff_step=diff_step,
                                   max_nfev=max_evaluations, xtol=1e-4, ftol=1e-6)
            plans = residuals.plans.get(result.x.tobytes()) or planner.plans(space.model_for(result.x))
        except Exception as error:  # the fit never raises once planning started: report it as failed
            return failed_result(model, space, f"{type(error).__name__}: {error}", residuals.evaluations,
                                 time.perf_counter() - t_begin, SSE_KIND)
    std = least_squares_std(result.fun, result.jac)
    status = FitStatus.CONVERGED if result.status > 0 else FitStatus.MAX_EVALUATIONS
    values, std_errors = space.values(result.x), space.natural_std_errors(result.x, std)
    unidentified = identification(values, space.start_values, std_errors)
    message = outcome_message("" if result.status > 0 else str(result.message), space.at_bounds(result.x), unidentified)
    if unidentified:
        status = FitStatus.UNIDENTIFIED
    rows = [{"condition": c, "distance_m": float(D), "width_m": float(w), "mt_recorded_s": float(mt),
             "mt_predicted_s": movement_time(plan.t, plan.ee_speed), "plan_status": plan.status, "plan_success": plan.success}
            for c, (D, w, mt, plan) in enumerate(zip(table.distance, table.width, table.mt, plans))]
    return FitResult(
        success=status == FitStatus.CONVERGED and all(plan.converged for plan in plans), status=status,
        message=message, model=fitted_model(space.model_for(result.x), model, f"movement times of {len(table.mt)} conditions"),
        values=values, initial_values=space.start_values, std_errors=std_errors, laplace_std_errors=dict(std_errors),
        objective=float(np.sum(result.fun**2)), objective_kind=SSE_KIND, evaluations=residuals.evaluations,
        fit_time=time.perf_counter() - t_begin, conditions=rows)


class _MovementTimeResiduals:
    """u -> predicted MT − given MT (m,), s; an unsettled reach or a rejected value counts as the horizon H·h."""

    def __init__(self, space: ParameterSpace, planner: ConditionPlanner, mt: np.ndarray, on_evaluation):
        self.space, self.planner, self.mt, self.on_evaluation = space, planner, mt, on_evaluation
        self.plans: dict[bytes, list] = {}
        self.evaluations = 0

    def __call__(self, u: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        try:
            model = self.space.model_for(u)
        except ValueError:
            residual = np.full(len(self.mt), self.space.model.duration) - self.mt
        else:
            plans = self.plans[np.asarray(u, dtype=float).tobytes()] = self.planner.plans(model)
            predicted = np.array([movement_time(plan.t, plan.ee_speed) for plan in plans])
            residual = np.where(np.isfinite(predicted), predicted, model.duration) - self.mt
        self.on_evaluation(float(np.sum(residual**2)))
        return residual


def least_squares_std(residual: np.ndarray, jacobian: np.ndarray, whitened: bool = False) -> np.ndarray:
    """sqrt(diag(s² (JᵀJ)⁻¹)) of residuals (m,) with their Jacobian (m, p): s² = SSE / (m − p) for residuals of unknown
    variance, s² = 1 for ``whitened`` ones (divided by their known standard deviations); NaN without spare residuals
    (unknown variance) or with a singular JᵀJ."""
    m, p = jacobian.shape
    information = jacobian.T @ jacobian
    if (m <= p and not whitened) or not np.all(np.isfinite(information)) or np.linalg.matrix_rank(information) < p:
        return np.full(p, np.nan)
    scale = 1.0 if whitened else np.sum(residual**2) / (m - p)
    return np.sqrt(np.diag(scale * np.linalg.inv(information)))
