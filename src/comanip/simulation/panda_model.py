"""The Franka Emika Panda as a MuJoCo model, converted from the URDF shipped with ``example-robot-data``.

MuJoCo's own URDF importer reads the links' real masses and inertias from the arm-only URDF of
:mod:`comanip.bodies.panda_urdf` (fingers fixed and closed, hand kept, end-effector link at the Franka
Hand's TCP: the same x_ee as the planning body). Before the import, visual and collision meshes are dropped
so that nothing but the URDF is read: links get simple capsules instead, for pictures only, and nothing in
the scene collides, so contact never enters the co-manipulation dynamics. Static bodies are kept (not
fused), so the TCP survives as a body.

Then MjSpec adds what the URDF lacks: the drives' reflected rotor inertia as joint armature (the values the
planning body uses, :data:`comanip.bodies.panda.PANDA_ARMATURE`), torque actuators with the URDF's effort
limits, a site at the TCP, and optionally the carried object (a rigid box welded at the TCP, its centre of
mass on the TCP) and a table. The model is converted at first use and cached in memory, keyed by the URDF's
SHA-256 and the options.
"""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from comanip.bodies.panda import PANDA_ARMATURE, READY_POSE
from comanip.bodies.panda_urdf import ARM_JOINTS, TCP_LINK, panda_urdf_path, reduced_panda_urdf
from comanip.caching.process_caches import memoised
from comanip.extras import require

mujoco = require("mujoco", "sim")

#: Site at the TCP: the controlled point, and the handle where the person pushes.
TCP_SITE = "tcp"
#: Body of the carried object (present when the model is built with an object).
OBJECT_BODY = "object"
#: The start posture (rad): elbow up, hand pointing down.
READY_POSTURE = np.array(READY_POSE)
#: Table top height (m) in the robot base frame; goals "on the table" lie above it.
TABLE_HEIGHT = 0.0


def urdf_hash(path: Path | None = None) -> str:
    """SHA-256 of the URDF file: the cache key of every model converted from it."""
    return hashlib.sha256(Path(path or panda_urdf_path()).read_bytes()).hexdigest()


def build_panda_model(object_mass: float = 0.0, object_size=(0.20, 0.10, 0.05), timestep: float = 1e-3,
                      table: bool = True) -> mujoco.MjModel:
    """A compiled MuJoCo model of the Panda arm with torque actuators on its 7 joints.

    Args:
        object_mass: mass (kg) of a box welded at the TCP, its centre of mass on the TCP; 0 for none.
        object_size: the box's full edge lengths (m) along the TCP frame's x, y, z (sets its inertia).
        timestep: simulation step (s); the controller runs once per step (1 kHz at the default).
        table: add a table top at :data:`TABLE_HEIGHT` (visual only).

    Returns:
        An ``MjModel`` with joints ``panda_joint1..7`` (q = qpos, 7 entries), one motor per joint
        (``ctrl`` in N·m, limited to the URDF efforts), and site :data:`TCP_SITE`.
    """
    if not (isinstance(object_mass, (int, float)) and np.isfinite(object_mass) and object_mass >= 0):
        raise ValueError(f"object_mass must be a finite number ≥ 0 (kg), got {object_mass!r}")
    if not (isinstance(timestep, (int, float)) and 0 < timestep <= 0.01):
        raise ValueError(f"timestep must be in (0, 0.01] s, got {timestep!r}")
    xml = _model_xml(urdf_hash(), float(object_mass), tuple(float(s) for s in object_size), float(timestep), bool(table))
    return mujoco.MjModel.from_xml_string(xml)


@memoised(maxsize=8)
def _model_xml(urdf_sha256: str, object_mass: float, object_size: tuple, timestep: float, table: bool) -> str:
    """MJCF text of the model (cached per URDF hash and options; the hash only keys the cache)."""
    spec = mujoco.MjSpec.from_string(_urdf_for_mujoco())
    spec.modelname = "panda_comanip"
    spec.option.timestep = timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.gravity = [0.0, 0.0, -9.81]
    _add_link_capsules(spec)
    tcp = spec.body(TCP_LINK)
    tcp.add_site(name=TCP_SITE, size=[0.01, 0.0, 0.0], rgba=[1.0, 0.3, 0.1, 1.0])
    if object_mass > 0:
        size = np.asarray(object_size)
        # the geom's mass gives the body a uniform box's inertia (MuJoCo computes it from the geom)
        tcp.add_body(name=OBJECT_BODY).add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=size / 2, mass=object_mass,
                                               contype=0, conaffinity=0, rgba=[0.85, 0.65, 0.2, 1.0])
    if table:
        spec.worldbody.add_geom(name="table", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.55, 0.6, 0.01],
                                pos=[0.4, 0.0, TABLE_HEIGHT - 0.01], contype=0, conaffinity=0,
                                rgba=[0.55, 0.45, 0.35, 1.0])
    spec.worldbody.add_light(pos=[0.5, 0.0, 2.0], dir=[0.0, 0.0, -1.0])
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.6, 0.6, 0.6]
    for name, armature in zip(ARM_JOINTS, PANDA_ARMATURE):
        joint = spec.joint(name)
        joint.armature = armature
        effort = joint.actfrcrange[1]
        spec.add_actuator(name=name.replace("joint", "motor"), target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT,
                          ctrllimited=True, ctrlrange=[-effort, effort])
    spec.compile()
    return spec.to_xml()


def _urdf_for_mujoco() -> str:
    """The arm-only URDF without meshes, MuJoCo's compiler told to keep static bodies and URDF efforts."""
    root = ET.fromstring(reduced_panda_urdf(hand=True))
    for link in root.findall("link"):
        for element in link.findall("visual") + link.findall("collision"):
            link.remove(element)
    extension = ET.SubElement(root, "mujoco")
    # autolimits turns the URDF efforts into joint actuator-force ranges, read back for the motors' ctrlrange
    ET.SubElement(extension, "compiler", {"fusestatic": "false", "discardvisual": "false", "autolimits": "true"})
    return ET.tostring(root, encoding="unicode")


def _add_link_capsules(spec: mujoco.MjSpec) -> None:
    """A capsule from each body's origin to each child's origin, for pictures (massless, never in contact)."""
    for body in spec.bodies:
        for child in body.bodies:
            offset = np.asarray(child.pos, dtype=float)
            if np.linalg.norm(offset) < 1e-3 or child.name in ("panda_leftfinger", "panda_rightfinger"):
                continue
            body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=np.r_[np.zeros(3), offset], size=[0.045, 0, 0],
                          contype=0, conaffinity=0, mass=0, rgba=[0.92, 0.92, 0.95, 1.0])
