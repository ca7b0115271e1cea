"""Fit model parameters to the timing of recorded reaches: the movement time and how early the speed peaks.

A recorded arm's path bows and its hand is seen by a tracker, so the likelihood of its positions under one
open-loop plan (:func:`comanip.fitting.fit_model`) can prefer a model whose covariance is wide enough to hold the
bow over one that moves in a person's time. This fit matches a person's timing: per condition (trials with one goal
and width; their starts averaged), the mean over the model's closed-loop executions
(:mod:`comanip.fitting.closed_loop_timing`) against the mean over the trials of two numbers, MT and t_peak/MT, each
reach timed alike (:func:`comanip.analysis.speed_profile.movement_timing`). The residuals are whitened by the standard error of the trials' mean, from the covariance of
the two numbers pooled over the conditions (each trial's deviation from its condition's mean), the model's own mean
over its executions taken to scatter as much per execution (the simulated method of moments), so the objective is a
chi² with 2·(conditions) − (parameters) degrees of freedom when the model can move as the people do. scipy's
``least_squares`` (trust region, bounded, forward differences in the transformed parameters) minimises it; the
standard errors are (JᵀJ)⁻¹ of the whitened residuals. A condition with an execution that does not settle counts as
lasting its 2·H steps with its peak at half of them.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from comanip.arguments import as_count, as_positive
from comanip.fitting.closed_loop_timing import recorded_timing
from comanip.fitting.condition_plans import ConditionPlanner
from comanip.fitting.conditions import Condition
from comanip.fitting.evaluation_progress import ProgressBar
from comanip.fitting.fit import grouped_trials
from comanip.fitting.fit_result import FitResult, FitStatus, failed_result, fitted_model, identification, outcome_message
from comanip.fitting.movement_times import least_squares_std
from comanip.fitting.parameters import MT_DEFAULT_PARAMETERS, ParameterSpace
from comanip.model import ReachingModel
from comanip.recordings.trial_files import Trial

CHI2_KIND = "chi² of the mean MT and t_peak/MT against the recordings'"


def fit_timing(model: ReachingModel, recordings: str | Path | Sequence[Trial], parameters: Sequence[str] = MT_DEFAULT_PARAMETERS,
               *, trials: str | Path | None = None, executions: int = 8, seed: int = 0, bounds: dict | None = None,
               max_evaluations: int = 60, diff_step: float = 0.02, scheduler=None, progress: bool = True,
               check_units: bool = True) -> FitResult:
    """Fit model fields so that the model's closed-loop reaches take the recorded reaches' time and peak as early.

    Args:
        model: the model to start from (other fields fixed); it executes its reaches with its own ``observation``.
        recordings: a recordings CSV, a folder of them or a motion-capture folder (docs/fitting.md), or a list of
            :class:`Trial`; each trial starts at rest at its first sample.
        parameters: free model fields (as in :func:`comanip.fitting.fit_model`; 'sigma_obs' has no meaning here).
        trials: a trials table with each trial's goal and width, when the recordings lack those columns.
        executions: closed-loop executions per condition whose timing is averaged (≥ 1).
        seed: seeds their motor and sensory noise, the same at every evaluation.
        bounds: {name: (low, high)} natural-unit bounds (default: a factor 1000 around the start).
        max_evaluations: evaluation budget of ``least_squares`` (finite-difference evaluations not counted).
        diff_step: relative finite-difference step in the transformed parameters.
        scheduler: None, a Dask scheduler address or a Client (as in ``fit_model``).
        progress: show a tqdm line.
        check_units: refuse recordings whose times look like ms or positions like mm (:mod:`comanip.units`).

    Returns:
        A :class:`FitResult` whose objective is the chi² (``objective_kind``) and whose conditions list each one's
        trials, recorded and predicted MT and t_peak/MT; status 'failed' (never an exception) when the fit breaks down.
    """
    if "sigma_obs" in parameters:
        raise ValueError("sigma_obs is the recordings' measurement noise; a timing fit has no use for it")
    executions = as_count("executions", executions)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an integer ≥ 0, got {seed!r}")
    max_evaluations = as_count("max_evaluations", max_evaluations)
    diff_step = as_positive("diff_step", diff_step, "relative step")
    data, conditions = grouped_trials(model, recordings, trials, np.inf, check_units)
    space = ParameterSpace(model, parameters, bounds=bounds)
    recorded = RecordedTiming(data, conditions, executions)
    reaches = [(c.start_state(model), c.goal, c.width) for c in conditions]
    t_begin = time.perf_counter()
    with ConditionPlanner(reaches, scheduler) as planner, ProgressBar("fit timing", progress) as bar:
        residuals = _TimingResiduals(space, planner, recorded, executions, int(seed), bar.record)
        try:
            low, high = np.array(space.bounds).T
            result = least_squares(residuals, space.initial, bounds=(low, high), method="trf", diff_step=diff_step,
                                   max_nfev=max_evaluations, xtol=1e-3, ftol=1e-4)
            predicted = residuals.timings(result.x)
        except Exception as error:  # the fit never raises once planning started: report it as failed
            return failed_result(model, space, f"{type(error).__name__}: {error}", residuals.evaluations,
                                 time.perf_counter() - t_begin, CHI2_KIND)
    status = FitStatus.CONVERGED if result.status > 0 else FitStatus.MAX_EVALUATIONS
    values = space.values(result.x)
    std_errors = space.natural_std_errors(result.x, least_squares_std(result.fun, result.jac, whitened=True))
    unidentified = identification(values, space.start_values, std_errors)
    settled = bool(np.all(np.isfinite(predicted)))
    message = outcome_message("" if result.status > 0 else str(result.message), space.at_bounds(result.x), unidentified)
    if not settled:
        message = "; ".join(part for part in (message, "an execution did not settle within 2·H steps") if part)
    if unidentified:
        status = FitStatus.UNIDENTIFIED
    return FitResult(
        success=status == FitStatus.CONVERGED and settled, status=status, message=message,
        model=fitted_model(space.model_for(result.x), model, f"the timing of {recorded.trial_count} recorded trials in "
                           f"{len(conditions)} conditions"),
        values=values, initial_values=space.start_values, std_errors=std_errors, laplace_std_errors=dict(std_errors),
        objective=float(np.sum(result.fun**2)), objective_kind=CHI2_KIND, evaluations=residuals.evaluations,
        fit_time=time.perf_counter() - t_begin, conditions=recorded.rows(predicted))


class RecordedTiming:
    """The recorded trials' timing per condition: each trial's (MT, t_peak/MT), their mean per condition and the
    whitening of a condition's difference from a model's mean over ``executions`` executions by the pooled covariance.

    Args:
        trials: the recorded trials; conditions: their conditions (indices into ``trials``); executions: the model's
            executions per condition.
    """

    def __init__(self, trials: list[Trial], conditions: list[Condition], executions: int):
        self.conditions = conditions
        timings = [recorded_timing(trial) for trial in trials]
        members = [[k for k in c.trials if np.isfinite(timings[k].movement_time)] for c in conditions]
        self.trial_count = sum(len(m) for m in members)
        if any(not m for m in members) or self.trial_count < len(conditions) + 2:
            raise ValueError(f"a timing fit needs every condition to hold a recorded trial that comes to rest, and 2 "
                             f"trials more than conditions in all; got {[len(m) for m in members]} settled trials in "
                             f"{len(conditions)} conditions")
        numbers = [np.array([[timings[k].movement_time, timings[k].peak_fraction] for k in m]) for m in members]
        self.counts = np.array([len(m) for m in members])
        self._standard_error = np.sqrt(1 / self.counts + 1 / executions)
        """per condition, the standard error of the difference of the two means in units of one reach's spread"""
        self.mean = np.array([x.mean(axis=0) for x in numbers])
        """(conditions, 2): the trials' mean MT (s) and t_peak/MT per condition."""
        self.median = np.array([np.median(x, axis=0) for x in numbers])
        deviations = np.concatenate([x - x.mean(axis=0) for x in numbers])
        covariance = deviations.T @ deviations / (self.trial_count - len(conditions))
        if not np.all(np.linalg.eigvalsh(covariance) > 0):
            raise ValueError("the recorded trials' MT and t_peak/MT do not vary independently (their pooled covariance "
                             "is singular): a timing fit needs trials that differ")
        self._whitening = np.linalg.inv(np.linalg.cholesky(covariance))

    def residuals(self, predicted: np.ndarray) -> np.ndarray:
        """Predicted (conditions, 2) minus the trials' mean, over the standard error of the difference: (2·conditions,)."""
        error = (predicted - self.mean) @ self._whitening.T
        return (error / self._standard_error[:, None]).ravel()

    def rows(self, predicted: np.ndarray) -> list[dict]:
        """One row per condition: its goal, width, trials, the recorded (mean, median) and the predicted (mean over the
        executions; NaN for an unsettled one) MT and t_peak/MT; ``predicted`` (conditions, 2)."""
        return [{"condition": c, "goal_m": cond.goal.tolist(), "width_m": float(cond.width), "trials": int(n),
                 "mt_recorded_mean_s": float(mean[0]), "mt_recorded_median_s": float(median[0]), "mt_predicted_s": float(mine[0]),
                 "peak_fraction_recorded_mean": float(mean[1]), "peak_fraction_recorded_median": float(median[1]),
                 "peak_fraction_predicted": float(mine[1])}
                for c, (cond, n, mean, median, mine) in enumerate(zip(self.conditions, self.counts, self.mean, self.median, predicted))]


class _TimingResiduals:
    """u -> whitened (MT, t_peak/MT) residuals (2·conditions,); a rejected value or an unsettled reach counts as a
    reach of 2·H steps peaking half-way."""

    def __init__(self, space: ParameterSpace, planner: ConditionPlanner, recorded: RecordedTiming, executions: int,
                 seed: int, on_evaluation):
        self.space, self.planner, self.recorded = space, planner, recorded
        self.executions, self.seed, self.on_evaluation = executions, seed, on_evaluation
        self._timings: dict[bytes, np.ndarray] = {}
        self.evaluations = 0

    def timings(self, u: np.ndarray) -> np.ndarray:
        """The conditions' predicted (MT, t_peak/MT) at u, the means over the executions (conditions, 2); NaN for a
        condition with an unsettled execution (computed once per u)."""
        key = np.asarray(u, dtype=float).tobytes()
        if key not in self._timings:
            executed = self.planner.timings(self.space.model_for(u), self.executions, self.seed)
            self._timings[key] = np.array([[np.mean([t.movement_time for t in runs]), np.mean([t.peak_fraction for t in runs])]
                                           for runs in executed])
        return self._timings[key]

    def __call__(self, u: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        unsettled = (2 * self.space.model.duration, 0.5)
        try:
            predicted = self.timings(u)
        except ValueError:
            predicted = np.full((len(self.recorded.conditions), 2), np.nan)
        predicted = np.where(np.isfinite(predicted).all(axis=1, keepdims=True), predicted, unsettled)
        residual = self.recorded.residuals(predicted)
        self.on_evaluation(float(np.sum(residual**2)))
        return residual
