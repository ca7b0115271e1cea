"""(p) The passive robot: zero stiffness throughout, so the person moves arm and object alone (the effort
reference: whatever a leading robot saves the person is measured against it)."""

from __future__ import annotations

import numpy as np

from comanip.simulation.policies.protocol import PolicyContext, Prediction


class PassivePolicy:
    """Never predicts, never leads."""

    name = "passive"
    leads_height = False
    update_interval = None

    def __init__(self, context: PolicyContext):
        self.context = context

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        pass

    def predict(self, t: float) -> Prediction | None:
        return None
