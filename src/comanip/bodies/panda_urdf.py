"""The Franka Emika Panda's URDF, as shipped by the PyPI package ``example-robot-data``, reduced to its arm.

The shipped ``panda.urdf`` holds the 7 revolute arm joints ``panda_joint1..7``, the flange ``panda_link8``
(0.107 m beyond joint 7), the Franka Hand (fixed, 0.73 kg) with its ``panda_hand_tcp`` frame 0.1034 m
beyond the flange, and two prismatic finger joints. The reduced model keeps the arm, makes the finger
joints fixed (closed fingers: their 2 × 15 g stay on the hand) or drops the hand and fingers altogether, and
adds one fixed, massless link :data:`TCP_LINK` at a chosen offset from the flange: the end effector x_ee.
Everything is read from the installed package; nothing is downloaded.
"""

from __future__ import annotations

import importlib.metadata
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from comanip.extras import MissingExtra, missing

#: The actuated joints, base to wrist.
ARM_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
#: The flange frame (tool mounting plate), parent of the end-effector link.
FLANGE_LINK = "panda_link8"
#: Name of the end-effector link added to the reduced URDF.
TCP_LINK = "comanip_tcp"
#: The Franka Hand's tool centre point (between the fingertips) in the flange frame, m: the URDF's
#: ``panda_hand_tcp`` (0.1034 m along the hand's z, which is the flange's z).
HAND_TCP_OFFSET = (0.0, 0.0, 0.1034)

_HAND_LINKS = ("panda_hand", "panda_hand_tcp", "panda_leftfinger", "panda_rightfinger")
_URDF_IN_PACKAGE = "robots/panda_description/urdf/panda.urdf"


def panda_urdf_path() -> Path:
    """Path of ``panda.urdf`` inside the installed ``example-robot-data`` distribution."""
    absent = missing("panda")
    if absent is not None:
        raise absent
    try:
        files = importlib.metadata.files("example-robot-data") or []
    except importlib.metadata.PackageNotFoundError:
        raise MissingExtra("panda", "example-robot-data") from None
    for file in files:
        if str(file).endswith(_URDF_IN_PACKAGE):
            return Path(file.locate())
    raise RuntimeError(f"example-robot-data is installed but holds no {_URDF_IN_PACKAGE}")


def reduced_panda_urdf(hand: bool = True, tcp_offset=HAND_TCP_OFFSET) -> str:
    """The arm-only URDF as a string.

    Args:
        hand: keep the Franka Hand's inertia (fingers fixed, closed); False for a bare flange.
        tcp_offset: position (3,) of the end-effector link :data:`TCP_LINK` in the flange frame, m.
    """
    root = ET.parse(panda_urdf_path()).getroot()
    for joint in root.findall("joint"):
        # adam's parser cannot take the finger joints (prismatic, one a mimic); they carry no arm motion.
        if joint.get("type") == "prismatic":
            joint.set("type", "fixed")
            for child in joint.findall("limit") + joint.findall("mimic") + joint.findall("axis"):
                joint.remove(child)
        # Franka's extra <dynamics> attributes (K, D, mu_*) are unknown to URDF parsers, which print a
        # warning for each; friction and damping come from the body's own parameters instead.
        for dynamics in joint.findall("dynamics"):
            joint.remove(dynamics)
    if not hand:
        for element in list(root):
            names = {element.get("name")} | {e.get("link") for e in element.findall("child")}
            if names & set(_HAND_LINKS):
                root.remove(element)
    offset = " ".join(repr(float(v)) for v in np.asarray(tcp_offset, dtype=float))
    ET.SubElement(root, "link", name=TCP_LINK)
    tcp_joint = ET.SubElement(root, "joint", name=f"{TCP_LINK}_joint", type="fixed")
    ET.SubElement(tcp_joint, "parent", link=FLANGE_LINK)
    ET.SubElement(tcp_joint, "child", link=TCP_LINK)
    ET.SubElement(tcp_joint, "origin", xyz=offset, rpy="0 0 0")
    return ET.tostring(root, encoding="unicode")


def arm_joint_limits(urdf: str) -> dict[str, np.ndarray]:
    """Limits of :data:`ARM_JOINTS` from a URDF string, each (7,): ``q_min``, ``q_max`` (rad),
    ``qdot_max`` (rad/s) and ``tau_max`` (N·m) from the ``lower``, ``upper``, ``velocity``, ``effort`` attributes."""
    joints = {j.get("name"): j.find("limit") for j in ET.fromstring(urdf).findall("joint")}
    rows = [[float(joints[name].get(key)) for key in ("lower", "upper", "velocity", "effort")] for name in ARM_JOINTS]
    q_min, q_max, qdot_max, tau_max = np.array(rows).T
    return {"q_min": q_min, "q_max": q_max, "qdot_max": qdot_max, "tau_max": tau_max}
