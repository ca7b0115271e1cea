"""How a person's arm holds the handle on the axes a partner leads: compliant, taking up the height it is led to.

In the paper's synchronisation task (VI-A) the person leads the horizontal motion and leaves the height to the
robot: on the axes they do not lead (the followed axes, index set F) they intend no motion of their own. Their arm
there keeps the force that held the object at rest before the reach, F_hold (the object's weight, mostly), and
complies around the height it is led to, which it takes up with a short lag:

    x_f' = (x_F - x_f) / tau,   x_f(0) = x_F(0)
    F_F = F_hold + K_f (x_f - x_F) + D_f (x_f' - xdot_F)

with x_F the handle on those axes, x_f the position the person holds there (the handle's, low-passed with time
constant tau), K_f and D_f the following arm's stiffness and damping. A robot that leads those axes moves the handle
and the person follows; the force beyond holding it costs them is K_f times the lag (about K_f tau xdot_F at a
steady speed) plus the damping on the lag's velocity. The intention reported on those axes is x_f plus the offset
that held the load at rest (the intention at t = 0 minus the hand), so it starts where the person held it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from comanip.arguments import as_positive


@dataclass(frozen=True)
class FollowingArm:
    """The person's arm on the axes a partner leads (module docstring)."""

    stiffness: float = 200.0
    """K_f (N/m). An arm that is led relaxes: people lower their arm's stiffness when the partner's coming motion is
    not known to them (a robot guiding people overground, Sci. Rep. 2022, doi:10.1038/s41598-022-23496-z), and a relaxed arm's endpoint
    stiffness lies at the low end of the 300–1500 N/m of a held posture (Mussa-Ivaldi et al. 1985) or below; 200 N/m
    is a relaxed, not a co-contracted, arm."""
    damping: float = 30.0
    """D_f (N·s/m): the holding arm's damping-to-stiffness ratio (0.15 s, :class:`PersonParameters`' 120 / 800)
    kept at the lower stiffness."""
    time_constant: float = 0.1
    """tau (s): how soon the person takes up the height they are led to, about the latency of the first voluntary
    correction of the arm to a push (long-latency responses at 50–100 ms, voluntary ones from about 100 ms)."""

    def __post_init__(self):
        as_positive("stiffness", self.stiffness, "N/m")
        as_positive("damping", self.damping, "N·s/m")
        as_positive("time_constant", self.time_constant, "s")


class FollowedAxes:
    """The held position and the force on the followed axes of one reach (module docstring).

    axes: the indices F of the followed axes (e.g. (2,): the height); arm: the following arm's impedance;
    holding_impedance: the person's arm impedance F(x_d, xdot_d, x, xdot) (3,) N, whose force with the intention at
    rest is the holding force F_hold.
    """

    def __init__(self, axes, arm: FollowingArm, holding_impedance):
        self.axes = list(axes)
        self.arm = arm
        self._holding_impedance = holding_impedance
        self._held = None

    def start(self, intended_position) -> None:
        """Begin a reach with the intention at rest at intended_position (3,) m: the next :meth:`apply` takes the
        hand as the held position and the arm's force around this intention, the hand at rest there, as F_hold."""
        self._rest = np.array(intended_position, dtype=float)
        self._held = None

    def apply(self, t: float, position: np.ndarray, velocity: np.ndarray, intended_position: np.ndarray,
              intended_velocity: np.ndarray, force: np.ndarray) -> None:
        """Replace, in place, the intention (3,) m, m/s and the force (3,) N on the followed axes by the following
        arm's, with the hand at position (3,) m, velocity (3,) m/s at time t (s)."""
        a, arm = self.axes, self.arm
        if not a:
            return
        if self._held is None:
            self._held, self._time, self._offset = position[a].copy(), t, self._rest[a] - position[a]
            self._holding = self._holding_impedance(self._rest, np.zeros(3), position, np.zeros(3))[a]
        else:
            self._held += (1.0 - np.exp(-(t - self._time) / arm.time_constant)) * (position[a] - self._held)
            self._time = t
        rate = (position[a] - self._held) / arm.time_constant
        intended_position[a] = self._held + self._offset
        intended_velocity[a] = rate
        force[a] = self._holding + arm.stiffness * (self._held - position[a]) + arm.damping * (rate - velocity[a])
