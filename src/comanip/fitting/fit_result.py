"""The outcome of a fit, in the spirit of scipy's OptimizeResult: status first, then the numbers."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

import numpy as np

from comanip import presets
from comanip.fitting.parameters import ParameterSpace
from comanip.model import ReachingModel

class FitStatus(StrEnum):
    """How a fit ended. A ``str``, like :class:`comanip.optim.Status`: it prints and serialises as its value."""

    CONVERGED = "converged"
    """The optimiser met its tolerances and the data determine every parameter."""
    UNIDENTIFIED = "unidentified"
    """The optimiser stopped, but no recorded sample was scored, or a parameter stayed at its start value without a
    standard error: the data say nothing about it."""
    MAX_EVALUATIONS = "max_evaluations"
    """The optimiser ran out of evaluations; the values are the best found."""
    FAILED = "failed"
    """An error stopped the fit; the values are the start."""


FIT_STATUSES = tuple(FitStatus)
"""Every :class:`FitStatus`, in order."""


@dataclass
class FitResult:
    """Fitted parameters of a :class:`ReachingModel` and how well the fitted model matches the data."""

    success: bool
    """True when the fit converged (status 'converged') and every condition's plan at the fitted values succeeded."""
    status: FitStatus
    """How the fit ended (:class:`FitStatus`)."""
    message: str
    """What happened, in words, where the status does not say it all ("" for a plain convergence)."""
    model: ReachingModel
    """The model with the fitted values (the start model when the fit failed)."""
    values: dict[str, float]
    """Fitted value of each free parameter, natural units."""
    initial_values: dict[str, float]
    """Start value of each free parameter."""
    std_errors: dict[str, float]
    """Standard errors used for inference (natural units; NaN when the curvature is not positive definite).
    Recordings fit: the robust (sandwich) errors; MT fit: least-squares errors s²(JᵀJ)⁻¹."""
    laplace_std_errors: dict[str, float]
    """Standard errors from the inverse Hessian of the objective alone (Laplace). For the recordings'
    pseudo-likelihood these are too small (docs/fitting.md)."""
    objective: float
    """Objective at the fitted values (see ``objective_kind``)."""
    objective_kind: str
    """'negative log-likelihood (nats)' or 'sum of squared MT errors (s²)'."""
    evaluations: int
    """Objective evaluations (each plans every condition once)."""
    fit_time: float
    """Wall time of the fit (s), standard errors included."""
    conditions: list[dict] = field(default_factory=list)
    """Residuals per condition (goal, width, MT recorded and predicted, ...)."""
    trials: list[dict] = field(default_factory=list)
    """Residuals per trial (empty for an MT fit)."""
    sigma_obs: float | None = None
    """Measurement-noise standard deviation (m) the likelihood used (fitted when among the parameters)."""
    curves: list[dict] = field(default_factory=list, repr=False)
    """Per-condition curves for the figure (not written to JSON)."""

    def to_dict(self) -> dict:
        """JSON-ready summary (everything but the model object and the curves)."""
        out = {name: getattr(self, name) for name in self.__dataclass_fields__ if name not in ("model", "curves")}
        out["model"] = self.model.config()
        return _plain(out)

    def save_json(self, path: str | Path) -> Path:
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    def save_yaml(self, path: str | Path) -> Path:
        """The fitted model as a YAML that ``comanip.presets.load`` and ``comanip plan --preset`` read."""
        return presets.save(self.model, path)

    def summary(self) -> str:
        values = ", ".join(f"{name} = {value:.4g} ± {self.std_errors[name]:.2g}" for name, value in self.values.items())
        return f"{self.status}: {values}; {self.objective_kind} {self.objective:.6g} after {self.evaluations} evaluations in {self.fit_time:.1f} s"


def outcome_message(optimiser: str, bounded: list[str], unidentified: str | None = None) -> str:
    """The optimiser's message ("" when it converged), then the parameters that ended at a search bound, or short
    of one the data do not exclude (``bounded``; if any), then why the data do not determine the fit
    (``unidentified``, :func:`identification`; if any)."""
    parts = [optimiser]
    if bounded:
        parts.append(f"{bounded} ended at a search bound, or short of one the data do not exclude: the data hardly "
                     f"constrain them there or the bounds are too tight (their standard errors are NaN)")
    if unidentified:
        parts.append(f"but {unidentified}")
    return "; ".join(part for part in parts if part)


def identification(values: dict[str, float], start: dict[str, float], std_errors: dict[str, float],
                   samples_used: int | None = None) -> str | None:
    """Why the data do not determine the fit, in words, or None when they do: no sample scored
    (``samples_used`` 0; e.g. times in ms, all past the horizon), or parameters left at their start values
    (to 1e-9 relative) with no finite standard error (the objective does not change with them)."""
    if samples_used == 0:
        return ("no recorded sample lies within the plans' horizon, so the likelihood ignores the data "
                "(times in ms instead of s?)")
    stuck = [name for name, value in values.items()
             if np.isclose(value, start[name], rtol=1e-9, atol=0.0) and not np.isfinite(std_errors.get(name, np.nan))]
    if stuck:
        return f"{stuck} stayed at their start values without a standard error: the data do not determine them"
    return None


def fitted_model(fitted: ReachingModel, start: ReachingModel, data: str) -> ReachingModel:
    """The fitted model, named '<start name>-fit', its description saying what it was fitted to."""
    return fitted.replace(name=f"{start.name}-fit", description=f"Fitted by comanip to {data}, starting from the {start.name!r} model.")


def failed_result(model: ReachingModel, space: ParameterSpace, message: str, evaluations: int, fit_time: float,
                  kind: str) -> FitResult:
    """A result with status 'failed': the start model and values, NaN errors and objective."""
    nan = {name: np.nan for name in space.names}
    return FitResult(success=False, status=FitStatus.FAILED, message=message, model=model, values=dict(space.start_values),
                     initial_values=space.start_values, std_errors=nan, laplace_std_errors=dict(nan),
                     objective=np.nan, objective_kind=kind, evaluations=evaluations, fit_time=fit_time)


def _plain(value):
    """Numbers and arrays as JSON types; non-finite floats as None."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if np.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value
