"""Named parameter sets (paper Table II), stored as YAML beside this file.

>>> model = comanip.presets.planar()
>>> comanip.presets.load("cartesian").H
50
>>> comanip.presets.save(model.replace(kappa=2e-2), "my_model.yaml"); comanip.presets.load("my_model.yaml")
"""

from __future__ import annotations

from pathlib import Path

import yaml

from comanip.model import ReachingModel

PRESET_DIR = Path(__file__).parent


def names() -> list[str]:
    """The built-in preset names."""
    return sorted(p.stem for p in PRESET_DIR.glob("*.yaml"))


def load(name_or_path: str | Path) -> ReachingModel:
    """A built-in preset by name, or a model from a YAML file written by :func:`save`."""
    path = PRESET_DIR / f"{name_or_path}.yaml"
    if not path.exists():
        path = Path(name_or_path)
        if path.suffix not in (".yaml", ".yml") or not path.exists():
            raise ValueError(f"preset must be one of {names()} or an existing .yaml file, got {str(name_or_path)!r}")
    with open(path) as f:
        config = yaml.safe_load(f)
    if not isinstance(config, dict):
        raise ValueError(f"{path} does not hold a model mapping (got {type(config).__name__})")
    return ReachingModel.from_config(config)


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


def franka() -> ReachingModel:
    """Franka Emika Panda (n = 7 joints, d = 3), H = 50, h = 0.035 s; start from ``model.body.home_position``."""
    return load("franka")
