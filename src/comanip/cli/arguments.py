"""Argument helpers shared by the subcommands."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from comanip import presets
from comanip.model import ReachingModel


def add_model_arguments(parser: argparse.ArgumentParser, default_preset: str = "planar") -> None:
    parser.add_argument("--preset", default=default_preset,
                        help=f"built-in preset ({', '.join(presets.names())}) or a model YAML file (default: %(default)s)")


def load_model(args: argparse.Namespace) -> ReachingModel:
    return presets.load(args.preset)


def vector(text: str) -> np.ndarray:
    """Parse '0.3,0' or '0.3 0' into a float array."""
    try:
        return np.array([float(v) for v in text.replace(",", " ").split()])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None


def output_dir(path: str) -> Path:
    out = Path(path)
    out.mkdir(parents=True, exist_ok=True)
    return out
