"""The co-manipulation plant: a Panda carrying an object under Cartesian impedance control, pushed at the handle.

One call of :meth:`CoManipulationWorld.step` is one control period (the MuJoCo step, 1 ms by default):
the controller reads the arm's state through its own kinematics backend (which does not know the object),
commands joint torques, the person's force acts on the object at the handle (the TCP), and MuJoCo
integrates the arm, the object and gravity.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from comanip.arguments import as_vector
from comanip.control.impedance import CartesianImpedanceController, ImpedanceGains, RobotState
from comanip.extras import require
from comanip.simulation.kinematics import MujocoKinematics
from comanip.simulation.panda_model import OBJECT_BODY, READY_POSTURE, build_panda_model

mujoco = require("mujoco", "sim")


class JointState(NamedTuple):
    """The arm's joints at one instant."""

    qpos: np.ndarray
    """Joint positions (7,), rad."""
    qvel: np.ndarray
    """Joint velocities (7,), rad/s."""


class CoManipulationWorld:
    """Panda + carried object in MuJoCo with a torque-level impedance controller at 1/timestep Hz.

    Args:
        gains: impedance gains (the translational stiffness can change later on :attr:`controller`).
        start_posture: joint posture (7,) rad at reset; also the controller's nullspace rest posture.
        object_mass: mass of the object held at the TCP (kg); the controller does not compensate it.
        timestep: simulation and control period (s).
    """

    def __init__(self, gains: ImpedanceGains | None = None, start_posture=READY_POSTURE, object_mass: float = 1.5,
                 timestep: float = 1e-3):
        self.model = build_panda_model(object_mass=object_mass, timestep=timestep)
        self.data = mujoco.MjData(self.model)
        self.kinematics = MujocoKinematics(build_panda_model(object_mass=0.0, timestep=timestep, table=False))
        self.start_posture = as_vector("start_posture", start_posture, self.model.nq, "rad")
        self.controller = CartesianImpedanceController(gains or ImpedanceGains(), rest_posture=self.start_posture,
                                                       torque_limit=self.model.actuator_ctrlrange[:, 1])
        self.object_mass = float(object_mass)
        self._object_id = self.model.body(OBJECT_BODY).id if object_mass > 0 else 0
        self.reset()
        self.rotation_rest = self.observe().rotation

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    @property
    def t(self) -> float:
        """Simulated time since the last reset (s)."""
        return float(self.data.time)

    def reset(self, qpos=None, qvel=None) -> None:
        """Back to time 0 at joints qpos (default: the start posture) with velocities qvel (default: rest);
        the controller forgets its damping design (its stiffness is kept)."""
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[:] = self.start_posture if qpos is None else qpos
        self.data.qvel[:] = 0.0 if qvel is None else qvel
        mujoco.mj_forward(self.model, self.data)
        self.controller.reset()

    def joint_state(self) -> JointState:
        """Copies of the joints' positions and velocities, e.g. to restore a settled state with :meth:`reset`."""
        return JointState(self.data.qpos.copy(), self.data.qvel.copy())

    def observe(self) -> RobotState:
        """The controller's view of the arm now: TCP pose, Jacobian, inertia, gravity torque."""
        return self.kinematics(self.data.qpos, self.data.qvel)

    def step(self, state: RobotState, handle_force, position_rest, velocity_rest=None) -> np.ndarray:
        """Advance one control period: impedance torques toward the rest motion (position (3,) m, velocity
        (3,) m/s or None), handle_force (3,) N at the TCP.

        ``state`` is :meth:`observe`'s result for the current instant. Returns the joint torques (7,), N·m.
        """
        tau = self.controller(state, position_rest, self.rotation_rest, velocity_rest)
        self.data.ctrl[:] = tau
        # the object's centre of mass is on the TCP, so a force there produces no moment
        self.data.xfrc_applied[self._object_id, :3] = handle_force
        mujoco.mj_step(self.model, self.data)
        return tau

    def handle_inertia(self, state: RobotState) -> np.ndarray:
        """Apparent inertia (3, 3), kg, that a force at the handle moves with the orientation held: the
        translational block of the arm's Lambda = (J M^-1 J^T)^-1 plus the object's mass."""
        J = state.jacobian
        Lambda = np.linalg.inv(J @ np.linalg.solve(state.mass_matrix, J.T))
        return Lambda[:3, :3] + self.object_mass * np.eye(3)

    def mechanical_energy(self) -> float:
        """Kinetic energy of arm and object plus the object's gravitational potential (J): the energy the
        closed loop can store when the arm's own gravity is compensated and no stiffness is set."""
        mujoco.mj_forward(self.model, self.data)  # positions and inertia of the current state, not the last step's
        mujoco.mj_energyVel(self.model, self.data)
        kinetic = float(self.data.energy[1])
        if not self._object_id:
            return kinetic
        g = -self.model.opt.gravity[2]
        return kinetic + float(self.model.body_mass[self._object_id] * g * self.data.xipos[self._object_id, 2])
