"""Fit model parameters to the timing of recorded reaches: the movement time and how early the speed peaks.

A recorded arm's path bows and its hand is seen by a tracker, so the likelihood of its positions under one
open-loop plan (:func:`comanip.fitting.fit_model`) can prefer a model whose covariance is wide enough to hold the
bow over one that moves in a person's time. This fit matches a person's timing: per condition (trials with one goal
and width; their starts averaged), the timing of the model's mean closed-loop reach against the timing of the
trials' mean reach, both timed alike (:mod:`comanip.fitting.closed_loop_timing`): MT and t_peak/MT. The residuals are
whitened by the covariance of their difference: the recorded mean reach's timing scatters as a bootstrap over its
trials says, the model's mean over its executions as much per execution as the trials per trial (the simulated
method of moments), so the objective is a chi² with 2·(conditions) − (parameters) degrees of freedom when the model
can move as the people do. scipy's ``least_squares`` (trust region, bounded, forward differences in the transformed
parameters) minimises it; the standard errors are (JᵀJ)⁻¹ of the whitened residuals. A mean reach that does not
settle within 2·H steps counts as lasting them, its peak half-way.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from comanip.arguments import as_count, as_positive
from comanip.analysis.speed_profile import ReachTiming
from comanip.fitting.closed_loop_timing import mean_reach_timing, recorded_velocities
from comanip.fitting.condition_plans import ConditionPlanner
from comanip.fitting.conditions import Condition
from comanip.fitting.evaluation_progress import ProgressBar
from comanip.fitting.fit import grouped_trials
from comanip.fitting.fit_result import FitResult, FitStatus, failed_result, fitted_model, identification, outcome_message
from comanip.fitting.movement_times import least_squares_std
from comanip.fitting.parameters import MT_DEFAULT_PARAMETERS, ParameterSpace
from comanip.model import ReachingModel
from comanip.recordings.trial_files import Trial

CHI2_KIND = "chi² of the mean reach's MT and t_peak/MT against the recordings'"

MIN_TRIALS = 3
"""Trials a condition needs (its mean reach's scatter is bootstrapped over them)."""
BOOTSTRAP_RESAMPLES = 200
"""Resamples of a condition's trials that give its mean reach's scatter."""
BOOTSTRAP_SEED = 0
"""Seeds the resampling, so a fit's whitening is the same at every run."""


def fit_timing(model: ReachingModel, recordings: str | Path | Sequence[Trial], parameters: Sequence[str] = MT_DEFAULT_PARAMETERS,
               *, trials: str | Path | None = None, width: float | None = None, executions: int = 8, seed: int = 0, bounds: dict | None = None,
               max_evaluations: int = 60, diff_step: float = 0.02, scheduler=None, progress: bool = True,
               check_units: bool = True) -> FitResult:
    """Fit model fields so that the model's mean closed-loop reach takes the recorded reaches' time and peaks as early.

    Args:
        model: the model to start from (other fields fixed); it executes its reaches with its own ``observation``.
        recordings: a recordings CSV, a folder of them or a motion-capture folder (docs/fitting.md), or a list of
            :class:`Trial`; each trial starts at rest at its first sample.
        parameters: free model fields (as in :func:`comanip.fitting.fit_model`; 'sigma_obs' has no meaning here).
        trials: a trials table with each trial's goal and width, when the recordings lack those columns.
        width: every trial's goal width (m) instead of the recordings' (a motion-capture folder gives its endpoints'
            spread, which is not the accuracy a model aims for: its closed-loop endpoints scatter far less).
        executions: closed-loop executions averaged into a condition's mean reach (≥ 1).
        seed: seeds their motor and sensory noise, the same at every evaluation.
        bounds: {name: (low, high)} natural-unit bounds (default: a factor 1000 around the start).
        max_evaluations: evaluation budget of ``least_squares`` (finite-difference evaluations not counted).
        diff_step: relative finite-difference step in the transformed parameters.
        scheduler: None, a Dask scheduler address or a Client (as in ``fit_model``).
        progress: show a tqdm line.
        check_units: refuse recordings whose times look like ms or positions like mm (:mod:`comanip.units`).

    Returns:
        A :class:`FitResult` whose objective is the chi² (``objective_kind``) and whose conditions list each one's
        trials, recorded (with standard errors) and predicted MT and t_peak/MT; status 'failed' (never an exception) when the fit breaks down.
    """
    if "sigma_obs" in parameters:
        raise ValueError("sigma_obs is the recordings' measurement noise; a timing fit has no use for it")
    executions = as_count("executions", executions)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an integer ≥ 0, got {seed!r}")
    max_evaluations = as_count("max_evaluations", max_evaluations)
    diff_step = as_positive("diff_step", diff_step, "relative step")
    data, conditions = grouped_trials(model, recordings, trials, np.inf, check_units, width)
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
    return _timing_result(model, space, result, predicted, recorded, len(conditions), residuals.evaluations, t_begin)


def _timing_result(model: ReachingModel, space: ParameterSpace, result, predicted: np.ndarray, recorded: "RecordedTiming",
                   condition_count: int, evaluations: int, t_begin: float) -> FitResult:
    """The :class:`FitResult` of a finished ``least_squares`` ``result`` (its status, values, standard errors and
    whether each is identified) with the ``predicted`` timings of the conditions."""
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
                           f"{condition_count} conditions"),
        values=values, initial_values=space.start_values, std_errors=std_errors, laplace_std_errors=dict(std_errors),
        objective=float(np.sum(result.fun**2)), objective_kind=CHI2_KIND, evaluations=evaluations,
        fit_time=time.perf_counter() - t_begin, conditions=recorded.rows(predicted))


class RecordedTiming:
    """The timing of each condition's recorded mean reach, and the whitening of a model's difference from it.

    Args:
        trials: the recorded trials; conditions: their conditions (indices into ``trials``); executions: the model's
            executions per mean reach.
    """

    def __init__(self, trials: list[Trial], conditions: list[Condition], executions: int):
        self.conditions = conditions
        small = [len(c.trials) for c in conditions if len(c.trials) < MIN_TRIALS]
        if small:
            raise ValueError(f"a timing fit needs at least {MIN_TRIALS} trials per condition (goal and width), got "
                             f"{[len(c.trials) for c in conditions]}")
        self.trial_count = len(trials)
        step = float(np.median(np.concatenate([np.diff(trial.t) for trial in trials])))
        rng = np.random.default_rng(BOOTSTRAP_SEED)
        self.timing, self.covariance, self._whitening = [], [], []
        for c in conditions:
            velocities = recorded_velocities([trials[k] for k in c.trials], step)
            timing = _numbers(mean_reach_timing(step, velocities.mean(axis=0)))
            if not np.all(np.isfinite(timing)):
                raise ValueError(f"the mean reach of the trials aiming at {np.round(c.goal, 4).tolist()} m does not come "
                                 f"to rest within them")
            resampled = np.array([_numbers(mean_reach_timing(step, velocities[rng.integers(len(c.trials), size=len(c.trials))].mean(axis=0)))
                                  for _ in range(BOOTSTRAP_RESAMPLES)])
            covariance = np.cov(resampled[np.isfinite(resampled).all(axis=1)].T)
            difference = covariance * (1 + len(c.trials) / executions)
            if not np.all(np.linalg.eigvalsh(difference) > 0):
                raise ValueError(f"the trials aiming at {np.round(c.goal, 4).tolist()} m do not vary in MT and t_peak/MT "
                                 f"independently: a timing fit needs trials that differ")
            self.timing.append(timing)
            self.covariance.append(covariance)
            self._whitening.append(np.linalg.inv(np.linalg.cholesky(difference)))

    def residuals(self, predicted: np.ndarray) -> np.ndarray:
        """Predicted (conditions, 2) minus the recorded timing, whitened by their difference's covariance: (2·conditions,)."""
        return np.concatenate([w @ (p - t) for w, p, t in zip(self._whitening, predicted, self.timing)])

    def rows(self, predicted: np.ndarray) -> list[dict]:
        """One row per condition: its goal, width, trials, the recorded mean reach's MT and t_peak/MT with their
        bootstrap standard errors, and the predicted ones (NaN when unsettled); ``predicted`` (conditions, 2)."""
        return [{"condition": k, "goal_m": c.goal.tolist(), "width_m": float(c.width), "trials": len(c.trials),
                 "mt_recorded_s": float(t[0]), "mt_recorded_se_s": float(np.sqrt(cov[0, 0])), "mt_predicted_s": float(p[0]),
                 "peak_fraction_recorded": float(t[1]), "peak_fraction_recorded_se": float(np.sqrt(cov[1, 1])),
                 "peak_fraction_predicted": float(p[1])}
                for k, (c, t, cov, p) in enumerate(zip(self.conditions, self.timing, self.covariance, predicted))]


def _numbers(timing: ReachTiming) -> np.ndarray:
    """(MT s, t_peak/MT) of a timing."""
    return np.array([timing.movement_time, timing.peak_fraction])


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
        """The conditions' predicted (MT, t_peak/MT) at u (conditions, 2), NaN where unsettled (computed once per u)."""
        key = np.asarray(u, dtype=float).tobytes()
        if key not in self._timings:
            self._timings[key] = np.array([_numbers(t) for t in self.planner.timings(self.space.model_for(u), self.executions, self.seed)])
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
