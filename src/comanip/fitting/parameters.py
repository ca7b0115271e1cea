"""The free parameters of a fit: named model fields, searched in an unbounded transformed space.

A name is a real-valued field of :class:`~comanip.model.ReachingModel` (``kappa``, ``nu``, ``gamma``,
``h``, ...), an entry of a tuple-valued field as ``field.index`` (e.g. ``activation.0``), or
``sigma_obs``, the standard deviation of the measurement noise (m), which belongs to the likelihood rather
than the model. ``gamma`` lies in (0, 1) and is searched as its logit; every other parameter is positive
and searched as its logarithm, so u = log(kappa) and the step from u to u + 0.1 changes kappa by 10.5 %.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from comanip.arguments import as_positive

if TYPE_CHECKING:  # the CLI reads DEFAULT_PARAMETERS without loading the model's solvers
    from comanip.model import ReachingModel

DEFAULT_PARAMETERS = ("kappa", "nu", "gamma")
"""The parameters a recordings fit frees by default."""
MT_DEFAULT_PARAMETERS = ("kappa", "gamma")
"""The parameters a movement-time fit frees by default."""

UNIT_INTERVAL = ("gamma",)
"""Parameters searched as logit(value), in (0, 1); all others as log(value), > 0."""

LOG_RANGE = np.log(1e3)
"""Default search range around the start value of a log parameter: a factor of 1000 either way."""
LOGIT_RANGE = 12.0
"""... and of a logit parameter: [-12, 12] (gamma from 6e-6 to 0.999994)."""


class ParameterSpace:
    """Maps a transformed vector u (p,) to a model and a measurement noise, and back."""

    def __init__(self, model: ReachingModel, names: Sequence[str], sigma_obs: float = 1e-3,
                 bounds: dict[str, tuple[float, float]] | None = None):
        """names: the free parameters (see the module); sigma_obs: measurement noise std (m), its start value
        when 'sigma_obs' is among the names; bounds: {name: (low, high)} in natural units (optional)."""
        if isinstance(names, str) or not names:
            raise ValueError(f"parameters must be a non-empty list of names such as ['kappa', 'gamma'], got {names!r}")
        if len(set(names)) != len(names):
            raise ValueError(f"parameters must not repeat a name, got {list(names)}")
        self.model = model
        self.names = tuple(names)
        self.sigma_obs = as_positive("sigma_obs", sigma_obs, "m, standard deviation of the measurement noise")
        self.start_values = {name: self.sigma_obs if name == "sigma_obs" else read_parameter(model, name) for name in self.names}
        """{name: start value}, natural units."""
        self.initial = np.array([_to_transformed(name, value) for name, value in self.start_values.items()])
        """Transformed start vector (p,)."""
        self.bounds = [self._bound(name, u, (bounds or {}).get(name)) for name, u in zip(self.names, self.initial)]
        unknown = set(bounds or {}) - set(self.names)
        if unknown:
            raise ValueError(f"bounds name {sorted(unknown)}, which are not among the parameters {list(self.names)}")

    def _bound(self, name: str, u0: float, natural: tuple[float, float] | None) -> tuple[float, float]:
        if natural is None:
            half = LOGIT_RANGE if name in UNIT_INTERVAL else LOG_RANGE
            return (-half, half) if name in UNIT_INTERVAL else (u0 - half, u0 + half)
        try:
            low, high = (_to_transformed(name, float(v)) for v in natural)
        except (TypeError, ValueError) as error:
            raise ValueError(f"bounds of {name} must be (low, high) in natural units within its domain, got {natural!r} "
                             f"({error})") from None
        if not low <= u0 <= high:
            raise ValueError(f"bounds of {name} are {tuple(natural)}, which exclude its start value {self.start_values[name]}")
        return low, high

    def values(self, u) -> dict[str, float]:
        """{name: natural value} of a transformed vector u (p,)."""
        return {name: _to_natural(name, x) for name, x in zip(self.names, u)}

    def model_for(self, u) -> ReachingModel:
        """The model with the free fields set from u (raises ValueError when the model rejects a value)."""
        model = self.model
        for name, value in self.values(u).items():
            if name != "sigma_obs":
                model = write_parameter(model, name, value)
        return model

    def noise_for(self, u) -> float:
        """Measurement noise std (m) at u."""
        return self.values(u).get("sigma_obs", self.sigma_obs)

    def at_bounds(self, u, tolerance: float = 0.1) -> list[str]:
        """Names of the parameters within tolerance (transformed units: 0.1 is 10 % for a log parameter) of a
        search bound at u. Along a direction the data hardly constrain, Nelder-Mead stops anywhere near the
        bound once the objective changes by less than its tolerance."""
        return [name for name, x, (low, high) in zip(self.names, u, self.bounds) if min(x - low, high - x) <= tolerance]

    def natural_std_errors(self, u, transformed_std, bounded: list[str] | None = None) -> dict[str, float]:
        """Standard errors in natural units by the delta method: se(theta) = |dtheta/du| se(u); NaN for a
        parameter at a search bound (``bounded``, default :meth:`at_bounds`), where the curvature says nothing about
        the uncertainty."""
        values = self.values(u)
        bounded = self.at_bounds(u) if bounded is None else bounded
        return {name: np.nan if name in bounded else float(_slope(name, values[name]) * s)
                for name, s in zip(self.names, transformed_std)}


def read_parameter(model: ReachingModel, name: str) -> float:
    """A real-valued model field ('kappa') or tuple entry ('activation.0'); ValueError when there is none."""
    field, index = _split(model, name)
    value = getattr(model, field)
    if index is not None:
        if not isinstance(value, tuple) or not -len(value) <= index < len(value):
            raise ValueError(f"parameter {name!r}: {field} is {value!r}, which has no entry {index}")
        value = value[index]
    if isinstance(value, (bool, int, np.integer)) or not isinstance(value, (float, np.floating)):
        raise ValueError(f"parameter {name!r} is {value!r}; only real-valued fields (e.g. kappa, nu, gamma) can be fitted")
    return float(value)


def write_parameter(model: ReachingModel, name: str, value: float) -> ReachingModel:
    """A copy of model with the field (or tuple entry) ``name`` set to value."""
    field, index = _split(model, name)
    if index is None:
        return model.replace(**{field: float(value)})
    entries = list(getattr(model, field))
    entries[index] = float(value)
    return model.replace(**{field: tuple(entries)})


def _split(model: ReachingModel, name: str) -> tuple[str, int | None]:
    field, _, index = str(name).partition(".")
    fields = [f for f in model.__dataclass_fields__ if f not in ("body", "name", "description")]
    if field not in fields:
        raise ValueError(f"unknown parameter {name!r}; fit model fields {fields} (tuple entries as field.index) or sigma_obs")
    if not index:
        return field, None
    if not index.lstrip("-").isdigit():
        raise ValueError(f"parameter {name!r}: the part after the dot must be an integer index")
    return field, int(index)


def _to_transformed(name: str, value: float) -> float:
    if name in UNIT_INTERVAL:
        if not 0 < value < 1:
            raise ValueError(f"{name} is {value!r}; it is fitted as a logit and needs a value in (0, 1) (e.g. 0.99 for 1.0)")
        return float(np.log(value / (1 - value)))
    if not value > 0:
        raise ValueError(f"{name} is {value!r}; it is fitted as a logarithm and needs a value > 0 (start it at e.g. 1e-3)")
    return float(np.log(value))


def _to_natural(name: str, u: float) -> float:
    return float(1 / (1 + np.exp(-u))) if name in UNIT_INTERVAL else float(np.exp(u))


def _slope(name: str, value: float) -> float:
    """dtheta/du at theta = value."""
    return value * (1 - value) if name in UNIT_INTERVAL else value
