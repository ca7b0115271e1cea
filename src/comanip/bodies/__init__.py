"""Body models: inertia, damping and kinematics as CasADi expressions behind one interface."""

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
    """Build a body from its :meth:`Body.config` dictionary (``{"type": ..., **parameters}``)."""
    config = dict(config)
    kind = config.pop("type", None)
    if kind not in BODY_TYPES:
        raise ValueError(f"body type must be one of {sorted(BODY_TYPES)}, got {kind!r}")
    module, cls = BODY_TYPES[kind].split(":")
    return getattr(import_module(module), cls)(**config)


__all__ = ["Body", "MuscleActuatedBody", "PointMass", "body_from_config", "BODY_TYPES"]
