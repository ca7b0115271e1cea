"""Body models: inertia, damping and kinematics as CasADi expressions behind one interface."""

import inspect
from importlib import import_module

from comanip.bodies.body import Body
from comanip.bodies.muscle import MuscleActuatedBody
from comanip.bodies.point_mass import PointMass

#: body ``type`` in a config -> "module:class"; imported on use so heavy bodies cost nothing until asked for.
BODY_TYPES = {
    "point_mass": "comanip.bodies.point_mass:PointMass",
    "panda": "comanip.bodies.panda:Panda",
}


def body_from_config(config: dict) -> Body:
    """Build a body from its :meth:`Body.config` dictionary (``{"type": ..., **parameters}``); ValueError naming
    the type, the unknown or missing parameters and the allowed ones for a config that does not fit."""
    if not isinstance(config, dict):
        raise ValueError(f"body must be a mapping such as {{type: point_mass, n: 2, mass: 2.0}}, got {config!r}")
    config = dict(config)
    kind = config.pop("type", None)
    if not isinstance(kind, str) or kind not in BODY_TYPES:
        raise ValueError(f"body type must be one of {sorted(BODY_TYPES)}, got {kind!r}")
    module, cls = BODY_TYPES[kind].split(":")
    body_class = getattr(import_module(module), cls)
    signature = inspect.signature(body_class)
    parameters = signature.parameters
    try:
        signature.bind(**config)
    except TypeError:
        required = [p for p, v in parameters.items() if v.default is inspect.Parameter.empty]
        raise ValueError(f"body of type {kind!r} takes the parameters {list(parameters)} ({required} required), "
                         f"got {sorted(config)}") from None
    return body_class(**config)


__all__ = ["Body", "MuscleActuatedBody", "PointMass", "body_from_config", "BODY_TYPES"]
