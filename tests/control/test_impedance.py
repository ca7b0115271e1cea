"""The torque-level Cartesian impedance controller on the MuJoCo Panda, and the Panda model against pinocchio."""

import numpy as np
import pytest
import scipy.linalg

from comanip.control import CartesianImpedanceController, ImpedanceGains
from comanip.control.impedance import modal_damping, orientation_error
from comanip.simulation.panda_model import READY_POSTURE, build_panda_model
from comanip.simulation.world import CoManipulationWorld

OBJECT_MASS = 1.5
G = 9.81


def test_mujoco_panda_matches_pinocchio_on_the_same_urdf():
    """Inertia (with the armature added), gravity torque, TCP position and Jacobian at random postures."""
    pin = pytest.importorskip("pinocchio")
    from comanip.bodies.panda import PANDA_ARMATURE
    from comanip.bodies.panda_urdf import TCP_LINK, reduced_panda_urdf
    from comanip.simulation.kinematics import MujocoKinematics

    model = pin.buildModelFromXML(reduced_panda_urdf(hand=True))
    data = model.createData()
    frame = model.getFrameId(TCP_LINK)
    kinematics = MujocoKinematics()
    rng = np.random.default_rng(3)
    for _ in range(5):
        q = READY_POSTURE + rng.uniform(-0.5, 0.5, 7)
        state = kinematics(q, np.zeros(7))
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T + np.diag(PANDA_ARMATURE)
        np.testing.assert_allclose(state.mass_matrix, M, atol=1e-5)
        np.testing.assert_allclose(state.gravity, pin.computeGeneralizedGravity(model, data, q), atol=1e-4)
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(state.position, data.oMf[frame].translation, atol=1e-9)
        J = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(state.jacobian, J, atol=1e-9)


def test_holds_the_pose_under_the_uncompensated_object_weight():
    """At 400 N/m the object's weight sags the TCP by m g / k along z only (36.8 mm), within 0.5 mm; the
    arm's own weight is compensated, so nothing else moves, and the arm comes to rest."""
    stiffness = 400.0
    world = CoManipulationWorld(ImpedanceGains(translational_stiffness=(stiffness,) * 3), object_mass=OBJECT_MASS)
    start = world.observe()
    for _ in range(2000):
        state = world.observe()
        world.step(state, np.zeros(3), start.position)
    state = world.observe()
    deviation = state.position - start.position
    assert abs(deviation[2] + OBJECT_MASS * G / stiffness) < 5e-4
    assert np.all(np.abs(deviation[:2]) < 5e-4)
    assert np.linalg.norm(orientation_error(start.rotation, state.rotation)) < 1e-3
    assert np.linalg.norm(state.velocity) < 1e-3


def test_zero_stiffness_is_passive():
    """No translational or nullspace stiffness, high rotational stiffness, no external force: the closed loop's
    energy (kinetic + the object's potential + the rotational spring's k_R (1 - cos theta)) never increases.
    The arm drifts under the uncompensated object weight; the window ends before any joint limit is hit."""
    gains = ImpedanceGains(translational_stiffness=(0.0, 0.0, 0.0), nullspace_stiffness=0.0)
    world = CoManipulationWorld(gains, object_mass=OBJECT_MASS)
    world.reset(qvel=np.random.default_rng(1).normal(0.0, 0.2, 7))

    def energy():
        state = world.observe()
        sin_theta = min(1.0, np.linalg.norm(orientation_error(world.rotation_rest, state.rotation)))
        return world.mechanical_energy() + gains.rotational_stiffness * (1.0 - np.cos(np.arcsin(sin_theta)))

    energies = [energy()]
    for k in range(500):
        state = world.observe()
        world.step(state, np.zeros(3), state.position)
        assert world.data.nefc == 0, "a joint limit was hit: the window is too long for this test"
        if k % 10 == 9:
            energies.append(energy())
    assert np.max(np.diff(energies)) < 1e-6 * energies[0]
    assert energies[-1] < energies[0]          # the rotational damping dissipates


def test_modal_damping_gives_every_mode_the_damping_ratio():
    """Against scipy's generalised eigenvectors V (K V = Lambda V diag(w), V^T Lambda V = I):
    V^T D V = diag(2 zeta sqrt(w)); zero stiffness along a direction gives zero damping there."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(6, 6))
    Lambda = A @ A.T + 0.5 * np.eye(6)
    stiffness = np.array([0.0, 0.0, 400.0, 60.0, 60.0, 60.0])
    D = modal_damping(np.linalg.inv(Lambda), stiffness, 0.7)
    w, V = scipy.linalg.eigh(np.diag(stiffness), Lambda)
    np.testing.assert_allclose(V.T @ D @ V, np.diag(2 * 0.7 * np.sqrt(np.maximum(w, 0))), atol=1e-6)
    assert np.all(np.linalg.eigvalsh(D) > -1e-9)
    assert np.linalg.matrix_rank(D, tol=1e-6) == 4


def test_nullspace_term_causes_no_task_acceleration():
    """With every Cartesian stiffness zero and the arm at rest away from its rest posture, the commanded
    torque beyond gravity is the projected nullspace term: J M^-1 (tau - g) = 0."""
    gains = ImpedanceGains(translational_stiffness=(0.0, 0.0, 0.0), rotational_stiffness=0.0, nullspace_stiffness=20.0)
    world = CoManipulationWorld(gains, object_mass=0.0)
    world.reset(qpos=READY_POSTURE + np.array([0.3, -0.2, 0.4, 0.2, -0.3, 0.2, 0.5]))
    state = world.observe()
    tau = world.controller(state, state.position, state.rotation)
    assert np.linalg.norm(tau - state.gravity) > 1.0          # the posture term is active...
    task_acceleration = state.jacobian @ np.linalg.solve(state.mass_matrix, tau - state.gravity)
    assert np.linalg.norm(task_acceleration) < 1e-9           # ...and invisible at the TCP


def test_stiffness_changes_at_run_time_and_bad_gains_are_rejected():
    controller = CartesianImpedanceController(ImpedanceGains(), READY_POSTURE)
    controller.translational_stiffness = [0.0, 0.0, 400.0]
    np.testing.assert_array_equal(controller.translational_stiffness, [0.0, 0.0, 400.0])
    with pytest.raises(ValueError, match="translational_stiffness"):
        controller.translational_stiffness = [0.0, -1.0, 400.0]
    with pytest.raises(ValueError, match="shape"):
        controller.translational_stiffness = [400.0, 400.0]
    with pytest.raises(ValueError, match="rotational_stiffness"):
        ImpedanceGains(rotational_stiffness=-5.0)
    with pytest.raises(ValueError, match="object_mass"):
        build_panda_model(object_mass=-1.0)
