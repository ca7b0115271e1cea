"""Named parameter sets (paper Table II), stored as YAML beside this file.

>>> model = comanip.presets.planar()
>>> comanip.presets.load("cartesian").H
50
>>> comanip.presets.save(model.replace(kappa=2e-2), "my_model.yaml"); comanip.presets.load("my_model.yaml")
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import yaml

if TYPE_CHECKING:  # imported where a model is made: listing the presets (comanip --help) needs no solver
    from comanip.model import ReachingModel

PRESET_DIR = Path(__file__).parent


def names() -> list[str]:
    """The built-in preset names."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))


def load(name_or_path: str | Path) -> ReachingModel:
    """A built-in preset by name, or a model from a YAML file written by :func:`save`.

    Raises ValueError with a one-line message for an unknown name, a path that is not a readable, non-empty
    YAML file, a YAML syntax error (with its line), and missing, unknown or mistyped model fields.
    """
    path = _preset_path(name_or_path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"cannot read {str(path)!r}: {getattr(error, 'strerror', None) or error}") from None
    try:
        config = yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or str(error).splitlines()[0]
        raise ValueError(f"{str(path)!r} is not valid YAML{where}: {problem}") from None
    if config is None:
        raise ValueError(f"{str(path)!r} is empty; a model YAML is a mapping such as the one `comanip.presets.save` writes")
    if not isinstance(config, dict):
        raise ValueError(f"{str(path)!r} does not hold a model mapping (got a {type(config).__name__})")
    from comanip.model import ReachingModel

    return ReachingModel.from_config(config)


def _preset_path(name_or_path: str | Path) -> Path:
    """The YAML file of a built-in preset name, or the given path if it is a .yaml/.yml file; else ValueError."""
    if isinstance(name_or_path, str) and name_or_path in names():
        return PRESET_DIR / f"{name_or_path}.yaml"
    path = Path(name_or_path)
    allowed = f"one of {names()} or a model .yaml file"
    if path.suffix not in (".yaml", ".yml"):
        raise ValueError(f"preset must be {allowed}, got {str(name_or_path)!r}")
    if path.is_dir():
        raise ValueError(f"{str(path)!r} is a directory; the preset must be {allowed}")
    if not path.is_file():
        raise ValueError(f"{str(path)!r} does not exist; the preset must be {allowed}")
    return path


def save(model: ReachingModel, path: str | Path) -> Path:
    """Write a model to YAML (readable by :func:`load`)."""
    path = Path(path)
    with open(path, "w") as f:
        yaml.safe_dump(model.config(), f, sort_keys=False)
    return path


def planar() -> ReachingModel:
    """Planar point mass (n = d = 2), H = 30, h = 0.02 s."""
    return load("planar")


def cartesian() -> ReachingModel:
    """Cartesian point mass (n = d = 3), H = 50, h = 0.055 s."""
    return load("cartesian")


def human() -> ReachingModel:
    """Human-like planar reaching (n = d = 2): the planar preset with muscle activation stages and arm viscosity."""
    return load("human")


def human_cartesian() -> ReachingModel:
    """The human preset in 3-D (n = d = 3), for the collaborative scenarios and 3-D recordings."""
    return load("human_cartesian")


def arm() -> ReachingModel:
    """A person's arm reaching in 3-D (n = d = 3): human_cartesian with a lighter hand and its own kappa and
    gamma, set so that its closed-loop reaches time like motion-capture arm reaches; for a tracked hand."""
    return load("arm")


def franka() -> ReachingModel:
    """Franka Emika Panda (n = 7 joints, d = 3), H = 50, h = 0.035 s; start from ``model.body.home_position``."""
    return load("franka")


def franka_rest() -> ReachingModel:
    """The franka preset with the speed costs (stop_weight 1, joint_velocity_weight 0.02 (s/rad)²): the arm ends
    at rest and does not swing its wrist after the hand has stopped (benchmarks/franka_rest.py)."""
    return load("franka_rest")
