"""A reaching model: a body plus the motor-control parameters of the paper (Table II, SPEC §5).

Every field of :class:`ReachingModel` is checked at construction, so a bad value fails before any
CasADi work. Symbols follow the paper: h, H, gamma, nu, kappa, W.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from comanip.belief.noise import check_noise_form
from comanip.bodies import Body, body_from_config
from comanip.objectives.discounting import check_discount_form
from comanip.objectives.reward import check_goal_covariance_form


@dataclass(frozen=True)
class ReachingModel:
    """Body and motor-control parameters of one human reaching model."""

    body: Body
    """Arm dynamics and kinematics (point mass or Panda)."""
    h: float
    """Time step (s), > 0."""
    H: int
    """Planning horizon (steps), ≥ 1; the plan spans H·h seconds."""
    gamma: float
    """Discount per step of the reward, in (0, 1]; the time cost of the cost–benefit trade-off."""
    nu: float
    """Effort weight on Σ||tau||² (reward units per (N·m)² or N²), ≥ 0."""
    kappa: float
    """Variance of the multiplicative motor-noise entries (dimensionless), ≥ 0; sqrt(kappa) is the
    coefficient of variation of the executed torque."""
    width: float
    """Default goal width w (m), > 0, used when a solve is given no width."""
    noise: str = "isotropic"
    """Noise covariance form: 'isotropic' (default), 'per_channel' or 'rank_one' (SPEC §2)."""
    goal_covariance: str = "std"
    """How W is built from w: 'std' W = w² I (default) or 'cov' W = w I (SPEC §3)."""
    discount: str = "exponential"
    """'exponential' gamma^i (default) or 'hyperbolic' 1/(1 + (1/gamma - 1) i)."""
    name: str = "custom"
    """Label used in file names and reports."""
    description: str = field(default="", compare=False)
    """Free text: where the parameters come from."""

    def __post_init__(self):
        if not isinstance(self.body, Body):
            raise ValueError(f"body must be a comanip.bodies.Body, got {type(self.body).__name__}")
        _check_positive("h", self.h, "s")
        if isinstance(self.H, bool) or not isinstance(self.H, (int, np.integer)) or self.H < 1:
            raise ValueError(f"H must be an integer ≥ 1 (horizon in steps), got {self.H!r}")
        object.__setattr__(self, "H", int(self.H))
        if not (isinstance(self.gamma, (int, float)) and 0 < self.gamma <= 1):
            raise ValueError(f"gamma must be in (0, 1] (discount per step), got {self.gamma!r}")
        _check_nonnegative("nu", self.nu, "reward per N²")
        _check_nonnegative("kappa", self.kappa, "dimensionless variance")
        _check_positive("width", self.width, "m")
        check_noise_form(self.noise)
        check_goal_covariance_form(self.goal_covariance)
        check_discount_form(self.discount)

    @property
    def n(self) -> int:
        """Degrees of freedom of the body."""
        return self.body.n

    @property
    def d(self) -> int:
        """Task-space dimension of the end effector."""
        return self.body.d

    @property
    def M(self):
        """Inertia (n, n): an array for a point mass; for a nonlinear body, a function q -> (n, n) array."""
        if self.body.is_linear:
            return np.asarray(self.body.mass_matrix_function(np.zeros(self.n)))
        return lambda q: np.asarray(self.body.mass_matrix_function(q))

    @property
    def D(self) -> np.ndarray:
        """Damping (n, n)."""
        return self.body.damping

    @property
    def duration(self) -> float:
        """Horizon length H·h (s)."""
        return self.H * self.h

    def replace(self, **changes) -> "ReachingModel":
        """A copy with some fields changed (checked again)."""
        return replace(self, **changes)

    def config(self) -> dict:
        """Plain-data form for YAML; :meth:`from_config` inverts it."""
        return {
            "name": self.name,
            "description": self.description,
            "body": self.body.config(),
            "h": self.h,
            "H": self.H,
            "gamma": self.gamma,
            "nu": self.nu,
            "kappa": self.kappa,
            "width": self.width,
            "noise": self.noise,
            "goal_covariance": self.goal_covariance,
            "discount": self.discount,
        }

    @classmethod
    def from_config(cls, config: dict) -> "ReachingModel":
        config = dict(config)
        allowed = set(cls.__dataclass_fields__)
        unknown = set(config) - allowed
        if unknown:
            raise ValueError(f"unknown model fields {sorted(unknown)}; allowed: {sorted(allowed)}")
        if "body" not in config:
            raise ValueError("a model config needs a 'body' entry, e.g. {type: point_mass, n: 2, mass: 2.0}")
        config["body"] = body_from_config(config["body"])
        return cls(**config)


def _check_positive(name, value, unit):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0 ({unit}), got {value!r}")


def _check_nonnegative(name, value, unit):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) or not math.isfinite(value) or value < 0:
        raise ValueError(f"{name} must be a finite number ≥ 0 ({unit}), got {value!r}")
