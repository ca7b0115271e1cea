"""(g) An admittance robot: it follows the person's force on the height instead of predicting anything. Its rest
height moves at the person's force beyond holding over an admittance damping,

    z_rest' = (F_z - F_z(0)) / D_a,   z_rest(0) = z(0),

F_z the person's force on the handle along z as a wrist force sensor reads it (F_z(0): the force that holds the
object at rest before the reach), and the robot's spring (the scenario's stiffness on z) pulls the handle there. The
person leads the height (:attr:`leads_height` is false): the robot moves only as far and as fast as it is pushed.
Re-predicted every update_interval; no goal estimate."""

from __future__ import annotations

import numpy as np

from comanip.arguments import as_positive
from comanip.simulation.policies.protocol import PolicyContext, Prediction

ADMITTANCE_DAMPING = 40.0
"""D_a (N·s/m): a push of 10 N beyond holding moves the rest at 0.25 m/s. Hand-guiding admittances of tens of N·s/m
are what co-manipulation labs run (a light one is easy to push and still damps the hand)."""


class AdmittancePolicy:
    """The rest height integrates the person's force beyond holding (module docstring)."""

    name = "admittance"
    leads_height = False

    def __init__(self, context: PolicyContext, damping: float = ADMITTANCE_DAMPING):
        self.context = context
        self.update_interval = context.update_interval
        self.damping = as_positive("damping", damping, "N·s/m")
        self.height = float(context.start[2])
        self.rate = 0.0
        self._holding = self._last = None

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        if self._holding is None:
            self._holding, self._last = float(force[2]), t
        self.height += self.rate * (t - self._last)
        self.rate = (float(force[2]) - self._holding) / self.damping
        self._last = t
        self._position = np.array(position, dtype=float)

    def predict(self, t: float) -> Prediction:
        """The rest at the integrated height moving at the present rate until the next update, then held; no goal (NaN)."""
        c = self.context
        times = c.rest_times(t) - t
        ahead = np.minimum(times, self.update_interval)
        position = np.tile(self._position, (len(times), 1))
        position[:, 2] = self.height + self.rate * ahead
        velocity = np.zeros_like(position)
        velocity[:, 2] = np.where(times < self.update_interval, self.rate, 0.0)
        return Prediction(np.full(3, np.nan), c.rest_from(t, position, velocity))
