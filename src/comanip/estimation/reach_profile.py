"""The normalised shape of a reach: the fraction of its distance covered, r(phi), over normalised time phi.

A reach of onset t_0, duration T and displacement Delta = g - x_0 puts the hand at

    x(t) = x_0 + Delta r(phi),   x'(t) = Delta r'(phi) / T,   phi = (t - t_0) / T,

with r(phi) = 0 before the onset (phi ≤ 0) and 1 after the end (phi ≥ 1). Here T is the movement time MT
(for a recorded movement or a model's plan the speed is at 5 % of its peak at phi = 0 and 1,
docs/formulation.md §6; the minimum-jerk shape runs from rest to rest), and r(1) = 1 means g is where the
hand stops. Three sources of a shape: the minimum-jerk reach, a reaching model's mean plan, and the mean
of recorded movements (:meth:`ReachProfile.from_recordings`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_POINTS = 201


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
    def from_speed(cls, t, speed, name: str) -> "ReachProfile":
        """The shape of a movement whose speed (K,) at times (K,) s rises from and falls to 5 % of its peak at
        the first and last samples: integrated, normalised to distance 1 and time 1."""
        t = np.asarray(t, dtype=float)
        speed = np.maximum(np.asarray(speed, dtype=float), 0.0)
        covered = np.r_[0.0, np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))]
        phase = np.linspace(0.0, 1.0, _POINTS)
        fraction = np.interp(phase, (t - t[0]) / (t[-1] - t[0]), covered / covered[-1])
        rate = np.interp(phase, (t - t[0]) / (t[-1] - t[0]), speed * (t[-1] - t[0]) / covered[-1])
        return cls(phase, fraction, rate, name)

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

    @classmethod
    def from_recordings(cls, recordings, name: str = "recorded people") -> "ReachProfile":
        """The mean shape of recorded movements (:class:`comanip.recordings.Recording`): each one's distance
        covered along the line from its start to its end, over its normalised time, averaged."""
        phase = np.linspace(0.0, 1.0, _POINTS)
        shapes = []
        for recording in recordings:
            inside = (recording.t >= recording.onset - 1e-9) & (recording.t <= recording.end_time + 1e-9)
            offset = recording.end - recording.start
            along = (recording.position[inside] - recording.start) @ offset / (offset @ offset)
            shapes.append(np.interp(phase, (recording.t[inside] - recording.onset) / recording.movement_time, along))
        fraction = np.clip(np.mean(shapes, axis=0), 0.0, None)
        fraction = np.maximum.accumulate(fraction) / fraction[-1]
        return cls(phase, fraction, np.gradient(fraction, phase), name)

    @classmethod
    def from_plan(cls, plan, name: str) -> "ReachProfile":
        """The shape of a plan's mean reach (a :class:`comanip.Plan` from rest), between 5 % of its peak speed."""
        speed = np.asarray(plan.ee_speed)
        inside = np.flatnonzero(speed >= 0.05 * speed.max())
        first, last = int(inside[0]), int(inside[-1])
        return cls.from_speed(plan.t[first:last + 1], speed[first:last + 1], name)

    def __call__(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(r(phi), r'(phi)) at normalised times ``phi`` (any shape); 0 before 0, (1, 0) after 1."""
        phi = np.asarray(phi, dtype=float)
        inside = (phi > 0) & (phi < 1)
        return (np.interp(phi, self.phase, self.fraction, left=0.0, right=1.0),
                np.where(inside, np.interp(phi, self.phase, self.rate), 0.0))

    @property
    def peak_phase(self) -> float:
        """phi of the peak speed."""
        return float(self.phase[int(np.argmax(self.rate))])
