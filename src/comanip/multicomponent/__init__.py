"""Multi-component reaching (paper II-B, VI-B): the transition from the fast initial sub-movement to the
corrective one, a model that predicts where it happens, and the robot→person authority handover built on it."""
