"""What a person sees of their own arm during a reach: [q; qdot] with sensory noise, some time late.

At step k the person receives y_k = [q; qdot]_{k-d} + v_k (2n,), the position and velocity of d steps ago
plus independent Gaussian noise v_k ~ N(0, R), R = diag(position_std² I_n, velocity_std² I_n). For a point
mass q is the hand position, so the standard deviations are in m and m/s (for a jointed arm in rad and
rad/s). Vision is late by about 100 ms, proprioception by 30–60 ms. The delay is given in seconds and
rounded to whole steps of the model's h (:meth:`Observation.delay_steps`): 0.1 s on h = 0.02 s is 5 steps,
0.03 s is 2 (half a step rounds up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_nonnegative


@dataclass(frozen=True)
class Observation:
    """Sensory noise and delay of the person's feedback; every field finite and ≥ 0, checked at construction."""

    position_std: float
    """Standard deviation of the seen position, each coordinate (m for a point mass)."""
    velocity_std: float
    """Standard deviation of the seen velocity, each coordinate (m/s for a point mass)."""
    delay: float = 0.0
    """Age of what is seen (s); rounded to whole steps of the model's h."""

    def __post_init__(self):
        object.__setattr__(self, "position_std", as_nonnegative("position_std", self.position_std, "m"))
        object.__setattr__(self, "velocity_std", as_nonnegative("velocity_std", self.velocity_std, "m/s"))
        object.__setattr__(self, "delay", as_nonnegative("delay", self.delay, "s"))

    @classmethod
    def of(cls, model) -> "Observation | None":
        """The observation a :class:`comanip.ReachingModel` asks for (its ``observation`` field), None without one."""
        return cls(*model.observation) if model.observation else None

    def delay_steps(self, h: float) -> int:
        """The delay in whole steps of h (s): delay / h rounded to the nearest integer, halves up."""
        # relative slack so that a delay of k.5 steps up to rounding (0.03 / 0.02) rounds up as stated
        return math.floor(self.delay / h * (1 + 1e-9) + 0.5)

    def noise_std(self, n: int) -> np.ndarray:
        """Standard deviations (2n,) of the measurement noise on [q; qdot]."""
        return np.repeat([self.position_std, self.velocity_std], n)

    def measure(self, state: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
        """A noisy measurement (2n,) of [q; qdot] = state[:2n] (state (nx,)). Noiseless settings draw no
        random numbers, so they leave rng's stream (the motor noise) as an exact-state run has it."""
        clean = np.array(state[: 2 * n], dtype=float)
        std = self.noise_std(n)
        return clean + std * rng.standard_normal(2 * n) if np.any(std > 0) else clean
