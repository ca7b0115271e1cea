"""The normalised shape of a reach: the fraction of its distance covered, r(phi), over normalised time phi.

A reach of onset t_0, duration T and displacement Delta = g - x_0 puts the hand at

    x(t) = x_0 + Delta r(phi),   x'(t) = Delta r'(phi) / T,   phi = (t - t_0) / T,

with r(phi) = 0 before the onset (phi ≤ 0) and 1 after the end (phi ≥ 1). Here T is the movement time MT
(for a model's plan the speed is at 5 % of its peak at phi = 0 and 1, docs/formulation.md §6; the
minimum-jerk shape runs from rest to rest), and r(1) = 1 means g is where the hand stops. Two sources of a
shape: the minimum-jerk reach (:meth:`ReachProfile.minimum_jerk`) and a movement's path along its line
(:meth:`ReachProfile.from_path`, a reaching model's mean reach in :mod:`comanip.estimation.model_reaches.paced_model`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

_POINTS = 201


class ProfilePoints(NamedTuple):
    """A shape read at normalised times phi (any shape)."""

    fraction: np.ndarray
    """r(phi): 0 before 0, 1 after 1."""
    rate: np.ndarray
    """r'(phi): 0 outside (0, 1)."""


@dataclass(frozen=True)
class ReachProfile:
    """r(phi) sampled at ``phase`` (P,) from 0 to 1, from 0 to 1 (above 1 during an overshoot), with its derivative."""

    phase: np.ndarray
    """Normalised times (P,) from 0 to 1."""
    fraction: np.ndarray
    """r at ``phase`` (P,), from 0 at phi = 0 to 1 at phi = 1."""
    rate: np.ndarray
    """dr/dphi at ``phase`` (P,)."""
    name: str = "profile"
    """Where the shape comes from."""

    @classmethod
    def from_path(cls, t, position, velocity, name: str) -> "ReachProfile":
        """The shape of a straight movement from its positions (K,) m and velocities (K,) m/s along its line at
        times (K,) s, the first and last samples its onset and end (an overshoot stays in: r may pass 1)."""
        t, position, velocity = (np.asarray(a, dtype=float) for a in (t, position, velocity))
        duration, distance = t[-1] - t[0], position[-1] - position[0]
        phase = np.linspace(0.0, 1.0, _POINTS)
        normalised = (t - t[0]) / duration
        return cls(phase, np.interp(phase, normalised, (position - position[0]) / distance),
                   np.interp(phase, normalised, velocity * duration / distance), name)

    @classmethod
    def minimum_jerk(cls) -> "ReachProfile":
        """The minimum-jerk reach, phi from its start to its end (speed 0 at both)."""
        s = np.linspace(0.0, 1.0, _POINTS)
        return cls(s, 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 * (1 - s) ** 2, "minimum jerk")

    def __call__(self, phi: np.ndarray) -> "ProfilePoints":
        """(r(phi), r'(phi)) at normalised times ``phi`` (any shape); 0 before 0, (1, 0) after 1."""
        phi = np.asarray(phi, dtype=float)
        inside = (phi > 0) & (phi < 1)
        return ProfilePoints(np.interp(phi, self.phase, self.fraction, left=0.0, right=1.0),
                             np.where(inside, np.interp(phi, self.phase, self.rate), 0.0))
