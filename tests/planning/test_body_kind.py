"""The kind of body (point mass or arm) is decided in one place of comanip.planning, planning/body_kind.py: no other
module of the package reads ``is_linear``. The check is tried on a source that does, so that it is known to catch one."""

import ast
from pathlib import Path

import numpy as np

import comanip
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.body_kind import Arm, PointMass, body_kind
from comanip.planning.starts import ArmStarts, PointMassStarts

PLANNING = Path(comanip.__file__).resolve().parent / "planning"
THE_PLACE = PLANNING / "body_kind.py"


def reads_of_is_linear(source: str) -> list[int]:
    """Line numbers where ``source`` reads an attribute ``is_linear`` (or names it in getattr)."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Attribute) and node.attr == "is_linear":
            lines.append(node.lineno)
        elif isinstance(node, ast.Constant) and node.value == "is_linear":
            lines.append(node.lineno)
    return lines


def choices_outside_the_place(folder: Path = PLANNING, place: Path = THE_PLACE) -> dict[str, list[int]]:
    """Per module of ``folder`` other than ``place``, the lines where it reads ``is_linear``."""
    return {str(path.relative_to(folder)): found for path in sorted(folder.rglob("*.py"))
            if path != place and (found := reads_of_is_linear(path.read_text()))}


def test_only_body_kind_chooses_by_the_kind_of_body():
    assert reads_of_is_linear(THE_PLACE.read_text()), "body_kind.py should be where the choice is made"
    assert choices_outside_the_place() == {}


def test_the_check_catches_a_second_place(tmp_path):
    (tmp_path / "body_kind.py").write_text("kind = body.is_linear\n")
    (tmp_path / "elsewhere.py").write_text("def f(model):\n    return 1 if model.body.is_linear else 2\n")
    (tmp_path / "indirect.py").write_text("flag = getattr(body, 'is_linear')\n")
    (tmp_path / "innocent.py").write_text("linear = True\n")
    assert choices_outside_the_place(tmp_path, tmp_path / "body_kind.py") == {"elsewhere.py": [2], "indirect.py": [1]}


def test_each_kind_builds_its_own_start_policy(planar_planner):
    assert isinstance(body_kind(comanip.presets.planar()), PointMass)
    assert isinstance(body_kind(comanip.presets.load("franka_rest")), Arm)
    assert isinstance(planar_planner.kind, PointMass) and isinstance(planar_planner.starts, PointMassStarts)
    assert not isinstance(planar_planner.starts, ArmStarts)
    assert planar_planner.goal_joints(ReachParameters(np.zeros(4), np.array([0.3, 0.0]), 0.02)) is None   # a point mass reaches every goal
