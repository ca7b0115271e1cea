"""Maximum-likelihood fit of a reaching model's parameters to recorded hand trajectories.

Every evaluation sets the free parameters, plans one reach per condition (cold, see
:mod:`comanip.fitting.condition_plans`) and scores the recorded samples under the plans' predicted mean and covariance
(:mod:`comanip.fitting.likelihood`). scipy's bounded Nelder-Mead searches the transformed parameters
(:mod:`comanip.fitting.parameters`); it needs no derivatives, which the planner does not provide with
respect to model parameters. Standard errors come from a central-difference Hessian at the optimum
(:mod:`comanip.fitting.uncertainty`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

from comanip.arguments import as_count, as_positive
from comanip.fitting.condition_plans import ConditionPlanner
from comanip.fitting.conditions import Condition, group_conditions
from comanip.fitting.objective import RecordingsObjective
from comanip.fitting.parameters import DEFAULT_PARAMETERS, ParameterSpace
from comanip.recordings.trial_files import Trial, load_recordings
from comanip.fitting.residuals import condition_curves, condition_residuals, trial_residuals
from comanip.fitting.evaluation_progress import ProgressBar
from comanip.fitting.fit_result import FitResult, FitStatus, failed_result, fitted_model, identification, outcome_message
from comanip.fitting.uncertainty import curvature
from comanip.model import ReachingModel

SIMPLEX_STEP = 0.5
"""Edge of Nelder-Mead's first simplex in transformed units (a factor e^0.5 = 1.65 for log parameters)."""

NLL_KIND = "negative log-likelihood (nats)"

LIKELIHOOD_MARGIN = 1.92
"""nats: a parameter whose nearest search bound has an NLL within this of the fit's is not bounded away from it by
the data (the bound lies inside the 95 % likelihood-ratio interval, chi²₁(0.95)/2; lenient for the pseudo-likelihood,
whose differences are inflated)."""


def fit_model(model: ReachingModel, recordings: str | Path | Sequence[Trial], parameters: Sequence[str] = DEFAULT_PARAMETERS,
              *, trials: str | Path | None = None, sigma_obs: float = 1e-3, bounds: dict | None = None,
              start_tolerance: float = 0.005, width: float | None = None, max_evaluations: int = 200, step: float = 0.05,
              scheduler=None, progress: bool = True, check_units: bool = True) -> FitResult:
    """Fit model fields to recorded reaches by maximum (pseudo-)likelihood.

    Args:
        model: the model to start from; its other fields stay fixed.
        recordings: a recordings CSV, a folder of them (format in docs/fitting.md), or a list of :class:`Trial`.
        parameters: free parameters: real model fields, tuple entries as 'field.index', or 'sigma_obs'.
        trials: a trials table with each trial's goal and width, when the recordings lack those columns.
        sigma_obs: measurement-noise standard deviation (m); its start value when fitted.
        bounds: {name: (low, high)} natural-unit search bounds (default: a factor 1000 around the start;
            gamma's logit in [-12, 12]).
        start_tolerance: trials whose starts differ by at most this (m), with equal goal and width, share a plan.
        width: every trial's goal width (m) instead of the recordings' (a motion-capture folder gives its endpoints'
            spread, which is not the accuracy a model aims for).
        max_evaluations: Nelder-Mead's evaluation budget (the standard errors add 2p + 2p(p-1) more).
        step: finite-difference step for the standard errors, in transformed units (0.05: 5 % in a log parameter).
        scheduler: None plans locally; a Dask scheduler address or Client plans the conditions on that cluster.
        progress: show a tqdm line with the evaluations and the best NLL so far.
        check_units: refuse recordings whose times look like ms or positions like mm (:mod:`comanip.units`).

    Returns:
        A :class:`FitResult`. Input errors raise ValueError before any planning; a fit that fails later
        returns a result with status 'failed'; one whose data do not determine a parameter, 'unidentified'.
    """
    data, conditions = grouped_trials(model, recordings, trials, start_tolerance, check_units, width)
    space = ParameterSpace(model, parameters, sigma_obs, bounds)
    max_evaluations = as_count("max_evaluations", max_evaluations)
    step = as_positive("step", step, "transformed units")
    t_begin = time.perf_counter()
    reaches = [(c.start_state(model), c.goal, c.width) for c in conditions]
    with ConditionPlanner(reaches, scheduler) as planner, ProgressBar("fit", progress) as bar:
        objective = RecordingsObjective(data, conditions, space, planner, on_evaluation=bar.record)
        try:
            u, status, message = _minimise(objective, space, max_evaluations)
            spread = curvature(objective.per_trial, u, step)
            bounded = unconstrained_by_bounds(objective, space, u)
            plans = objective.plans(u)
        except Exception as error:  # the fit never raises once planning started: report it as failed
            return failed_result(model, space, f"{type(error).__name__}: {error}", objective.evaluations,
                                 time.perf_counter() - t_begin, NLL_KIND)
    fitted = fitted_model(space.model_for(u), model, f"{len(data)} recorded trials in {len(conditions)} conditions")
    curves = [condition_curves(data, c, plan) for c, plan in zip(conditions, plans)]
    trial_rows = trial_residuals(data, conditions, plans)
    values, std_errors = space.values(u), space.natural_std_errors(u, spread.robust_std(), bounded)
    unidentified = identification(values, space.start_values, std_errors, sum(row["samples_used"] for row in trial_rows))
    message = outcome_message(message, bounded, unidentified)
    if unidentified:
        status = FitStatus.UNIDENTIFIED
    return FitResult(
        success=status == FitStatus.CONVERGED and all(plan.converged for plan in plans), status=status,
        message=message, model=fitted, values=values, initial_values=space.start_values, std_errors=std_errors,
        laplace_std_errors=space.natural_std_errors(u, spread.laplace_std(), bounded),
        objective=objective(u), objective_kind=NLL_KIND, evaluations=objective.evaluations,
        fit_time=time.perf_counter() - t_begin, conditions=condition_residuals(trial_rows, conditions, plans, curves),
        trials=trial_rows, sigma_obs=space.noise_for(u), curves=curves)


def recordings_nll(model: ReachingModel, recordings: str | Path | Sequence[Trial], *, trials: str | Path | None = None,
                   sigma_obs: float = 1e-3, start_tolerance: float = 0.005, scheduler=None, check_units: bool = True) -> float:
    """The negative log-likelihood (nats) :func:`fit_model` minimises, at the model as given."""
    data, conditions = grouped_trials(model, recordings, trials, start_tolerance, check_units)
    space = ParameterSpace(model, ("sigma_obs",), sigma_obs)
    with ConditionPlanner([(c.start_state(model), c.goal, c.width) for c in conditions], scheduler) as planner:
        return RecordingsObjective(data, conditions, space, planner)(space.initial)


def grouped_trials(model, recordings, trials_table, start_tolerance, check_units,
                   width: float | None = None) -> tuple[list[Trial], list[Condition]]:
    """Checked trials and their conditions; ``width`` (m), when given, replaces every trial's goal width."""
    if not isinstance(model, ReachingModel):
        raise ValueError(f"model must be a comanip.ReachingModel (e.g. comanip.presets.planar()), got {type(model).__name__}")
    if isinstance(recordings, (str, Path)):
        trials = load_recordings(recordings, trials_table, check_units=check_units)
    else:
        trials = list(recordings)
        if not trials or not all(isinstance(trial, Trial) for trial in trials):
            raise ValueError("recordings must be a CSV path, a folder of CSVs or a non-empty list of comanip.fitting.Trial")
    wrong = [trial for trial in trials if trial.position.shape[1] != model.d]
    if wrong:
        raise ValueError(f"trial {wrong[0].name!r} has {wrong[0].position.shape[1]}-D positions; the {model.name!r} "
                         f"model's hand moves in {model.d}-D")
    if isinstance(start_tolerance, bool) or not isinstance(start_tolerance, (int, float)) or not start_tolerance >= 0:
        raise ValueError(f"start_tolerance must be a number ≥ 0 (m), got {start_tolerance!r}")
    if width is not None:
        width = as_positive("width", width, "m, the goal width of every trial")
        trials = [replace(trial, width=width) for trial in trials]
    return trials, group_conditions(trials, float(start_tolerance))


def unconstrained_by_bounds(objective, space: ParameterSpace, u) -> list[str]:
    """The free parameters at a search bound (:meth:`ParameterSpace.at_bounds`), then those whose nearest bound the
    data do not exclude: the objective (NLL) with that parameter moved onto the bound, the others as fitted, is within
    ``LIKELIHOOD_MARGIN`` of its value at u (p,). Along such a flat direction Nelder-Mead stops anywhere, and the
    curvature there says nothing about the uncertainty. One evaluation per parameter not at a bound."""
    u = np.asarray(u, dtype=float)
    names, fitted = space.at_bounds(u), objective(u)
    for i, (name, (low, high)) in enumerate(zip(space.names, space.bounds)):
        if name in names:
            continue
        moved = u.copy()
        moved[i] = low if u[i] - low <= high - u[i] else high
        if objective(moved) - fitted <= LIKELIHOOD_MARGIN:
            names.append(name)
    return names


def _minimise(objective, space: ParameterSpace, max_evaluations: int) -> tuple[np.ndarray, FitStatus, str]:
    """Bounded Nelder-Mead from the start values: (best u, status 'converged' or 'max_evaluations', SciPy's
    message when it did not converge, else "")."""
    u0 = space.initial
    if not np.isfinite(objective(u0)):
        raise RuntimeError("the objective is not finite at the start values (a plan is not finite or the model rejected a value)")
    simplex = [u0]
    for i, (low, high) in enumerate(space.bounds):
        vertex = u0.copy()
        vertex[i] = np.clip(u0[i] + (SIMPLEX_STEP if u0[i] + SIMPLEX_STEP <= high else -SIMPLEX_STEP), low, high)
        simplex.append(vertex)
    result = minimize(objective, u0, method="Nelder-Mead", bounds=space.bounds,
                      options={"initial_simplex": np.array(simplex), "xatol": 1e-3, "fatol": 1e-2, "maxfev": max_evaluations})
    status = FitStatus.CONVERGED if result.success else FitStatus.MAX_EVALUATIONS
    return np.asarray(result.x), status, "" if result.success else str(result.message)
