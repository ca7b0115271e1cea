"""MuJoCo as the controller's kinematics and dynamics backend: (q, qdot) -> :class:`RobotState`.

It holds its own model of the arm alone, so the carried object is unknown to the controller (its weight
is not compensated, as in the paper's experiments), whatever the simulated plant carries.
"""

from __future__ import annotations

import numpy as np

from comanip.control.impedance import RobotState
from comanip.extras import require
from comanip.simulation.panda_model import TCP_SITE, build_panda_model

mujoco = require("mujoco", "sim")


class MujocoKinematics:
    """Pose, Jacobian, inertia and gravity torque of the TCP site of a MuJoCo arm model (no object by default)."""

    def __init__(self, model: mujoco.MjModel | None = None, site: str = TCP_SITE):
        self.model = model if model is not None else build_panda_model(object_mass=0.0, table=False)
        self.data = mujoco.MjData(self.model)
        self.site_id = self.model.site(site).id
        nv = self.model.nv
        self._jacobian = np.zeros((6, nv))
        self._mass_matrix = np.zeros((nv, nv))
        self._gravity = np.zeros(nv)

    def __call__(self, q, qdot) -> RobotState:
        """State of the arm at joints q (n,) rad moving at qdot (n,) rad/s."""
        model, data = self.model, self.data
        data.qpos[:] = q
        data.qvel[:] = 0.0  # with zero velocity the recursive Newton-Euler bias is gravity alone
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_crb(model, data)
        mujoco.mj_jacSite(model, data, self._jacobian[:3], self._jacobian[3:], self.site_id)
        mujoco.mj_fullM(model, data, self._mass_matrix)
        mujoco.mj_rne(model, data, 0, self._gravity)
        return RobotState(q=np.array(q, dtype=float), qdot=np.array(qdot, dtype=float),
                          position=data.site_xpos[self.site_id].copy(),
                          rotation=data.site_xmat[self.site_id].reshape(3, 3).copy(),
                          jacobian=self._jacobian.copy(), mass_matrix=self._mass_matrix.copy(),
                          gravity=self._gravity.copy())
