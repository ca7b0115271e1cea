"""The Panda body against pinocchio (an independent rigid-body library reading the unreduced URDF), its
belief propagation against Monte Carlo of the noisy nonlinear step, its stability, limits, IK and config."""

import casadi as ca
import numpy as np
import pytest

import comanip
from comanip.belief import end_effector_belief, propagate_belief, sample_trajectories
from comanip.belief.propagation import linearised_step_function
from comanip.bodies import body_from_config
from comanip.bodies.panda import Panda
from comanip.bodies.panda_urdf import panda_urdf_path
from comanip.planning.starts.initial_guess import minimum_jerk_torques

pytestmark = pytest.mark.slow  # the Panda's dynamics and Monte Carlo of its nonlinear step

pin = pytest.importorskip("pinocchio")

H_FRANKA = 0.035  # the franka preset's step (s)


@pytest.fixture(scope="module")
def panda():
    return Panda(gravity=True)


@pytest.fixture(scope="module")
def pinocchio_panda():
    """Pinocchio's model of the shipped URDF with the finger joints locked closed, and its data."""
    full = pin.buildModelFromUrdf(str(panda_urdf_path()))
    fingers = [full.getJointId(name) for name in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, fingers, pin.neutral(full))
    model.gravity.linear = np.array([0.0, 0.0, -9.80665])  # adam's standard gravity (pinocchio's default is 9.81)
    return model, model.createData()


def random_configurations(body, count, rng):
    return rng.uniform(body.q_min, body.q_max, size=(count, body.n))


def test_dynamics_and_kinematics_match_pinocchio(panda, pinocchio_panda, rng):
    """M(q) (less the added armature), x_ee(q), J(q), G(q) agree with pinocchio at the Franka Hand's TCP."""
    model, data = pinocchio_panda
    tcp = model.getFrameId("panda_hand_tcp")
    q_sym = ca.SX.sym("q", panda.n)
    autodiff_jacobian = ca.Function("J_ad", [q_sym], [ca.jacobian(panda.end_effector(q_sym), q_sym)])
    for q in random_configurations(panda, 25, rng):
        M = np.asarray(panda.mass_matrix_function(q)) - np.diag(panda.armature)
        M_pin = pin.crba(model, data, q)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        np.testing.assert_allclose(M, M_pin, rtol=0, atol=1e-8)

        x, J = (np.asarray(v) for v in panda.kinematics_function(q))
        pin.framesForwardKinematics(model, data, q)
        J_pin = pin.computeFrameJacobian(model, data, q, tcp, pin.LOCAL_WORLD_ALIGNED)[:3]
        np.testing.assert_allclose(x.ravel(), data.oMf[tcp].translation, rtol=0, atol=1e-8)
        np.testing.assert_allclose(J, J_pin, rtol=0, atol=1e-8)
        np.testing.assert_allclose(np.asarray(autodiff_jacobian(q)), J_pin, rtol=0, atol=1e-8)

        G = np.asarray(panda.gravity_function(q)).ravel()
        np.testing.assert_allclose(G, pin.computeGeneralizedGravity(model, data, q), rtol=0, atol=1e-8)


def test_flange_without_hand_matches_pinocchio_on_the_same_urdf(rng):
    """A bare flange (no hand, zero TCP offset): x_ee is pinocchio's panda_link8 and M loses the hand."""
    flange = Panda(hand=False, tcp_offset=np.zeros(3), armature=np.zeros(7))
    with_hand = Panda(armature=np.zeros(7))
    model = pin.buildModelFromXML(flange.urdf)
    data = model.createData()
    link8 = model.getFrameId("panda_link8")
    for q in random_configurations(flange, 20, rng):
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(np.asarray(flange.kinematics_function(q)[0]).ravel(), data.oMf[link8].translation, atol=1e-8)
        M = np.asarray(flange.mass_matrix_function(q))
        M_pin = pin.crba(model, data, q)
        np.testing.assert_allclose(M, np.triu(M_pin) + np.triu(M_pin, 1).T, rtol=0, atol=1e-8)
        # The hand only adds inertia: M_hand - M_flange is positive semi-definite and not zero.
        extra = np.linalg.eigvalsh(np.asarray(with_hand.mass_matrix_function(q)) - M)
        assert extra.min() > -1e-12 and extra.max() > 1e-3


def test_joint_limits_are_the_urdf_limits(panda, pinocchio_panda):
    model, _ = pinocchio_panda
    np.testing.assert_array_equal(panda.q_min, model.lowerPositionLimit)
    np.testing.assert_array_equal(panda.q_max, model.upperPositionLimit)
    np.testing.assert_array_equal(panda.qdot_max, model.velocityLimit)
    np.testing.assert_array_equal(panda.tau_max, model.effortLimit)
    assert np.all(panda.q_min < panda.home_position) and np.all(panda.home_position < panda.q_max)
    outside = panda.q_max + 1.0
    np.testing.assert_array_equal(panda.clip_to_limits(outside), panda.q_max)
    point_mass = comanip.presets.planar().body
    assert np.all(np.isinf(point_mass.q_max)) and np.all(np.isinf(point_mass.tau_max))


def test_euler_step_is_stable_with_armature_and_flips_the_wrist_without(rng):
    """SPEC §10: at h = 0.035 s, D = 0.3 I the velocity block of A has eigenvalues in (0, 1) with the
    rotor inertia; the bare URDF gives a negative one (the wrist velocity flips sign every step)."""
    model = comanip.presets.franka()
    step = linearised_step_function(model.body, model.h)
    bare_step = linearised_step_function(Panda(armature=np.zeros(7)), model.h)
    n = model.n
    configurations = random_configurations(model.body, 20, rng)
    for q in configurations:
        s = np.concatenate([q, rng.normal(0, 0.5, n)])
        A = np.asarray(step(s, rng.normal(0, 5, n))[1])
        eig = np.linalg.eigvals(A[n:, n:])
        assert np.all(np.abs(eig) < 1) and np.all(eig.real > 0), eig
    bare_eig = np.linalg.eigvals(np.asarray(bare_step(np.concatenate([model.body.home_position, np.zeros(n)]), np.zeros(n))[1])[n:, n:])
    assert bare_eig.real.min() < -0.3


def test_belief_matches_monte_carlo_of_the_nonlinear_step(rng):
    """Small noise: the linearised end-effector covariance at mid-reach and at the end agrees with the
    sample covariance of Monte Carlo through the nonlinear step and x_ee within 5 %."""
    model = comanip.presets.franka()
    body, kappa = model.body, 1e-3
    start = np.concatenate([body.home_position, np.zeros(body.n)])
    x_start = np.asarray(body.kinematics_function(body.home_position)[0]).ravel()
    goal_q = body.inverse_kinematics(x_start + np.array([0.1, 0.25, -0.1]), body.home_position)
    torque = minimum_jerk_torques(body, model.h, model.H, start, goal_q, 0.6 * model.duration)
    mean, cov = propagate_belief(body, model.h, kappa, start, torque)
    ee_mean, ee_cov = end_effector_belief(body, mean, cov)

    states = sample_trajectories(body, model.h, kappa, start, torque, 10000, rng)
    forward = body.kinematics_function.map(states.shape[0])
    for i in (model.H // 3, model.H):
        x = np.asarray(forward(states[:, i, : body.n].T)[0]).T
        sample_cov = np.cov(x.T)
        relative = np.linalg.norm(sample_cov - ee_cov[i]) / np.linalg.norm(ee_cov[i])
        assert relative < 0.05, (i, relative)
        # The hand moves (this is a reach), and the sampled mean is off mu_x = x_ee(mu_q) only by the small
        # second-order bias of the curved kinematics: a fraction of the spread.
        assert np.linalg.norm(ee_mean[i] - x_start) > 0.05
        std = np.sqrt(np.diag(ee_cov[i]))
        assert np.all(np.abs(x.mean(axis=0) - ee_mean[i]) < 0.2 * std + 5 * std / np.sqrt(len(x)))


def test_inverse_kinematics_reaches_the_workspace_within_limits(rng):
    body = comanip.presets.franka().body
    for q_target in random_configurations(body, 30, rng):
        x_target = np.asarray(body.kinematics_function(q_target)[0]).ravel()
        q = body.inverse_kinematics(x_target, body.home_position)
        assert np.all(q >= body.q_min) and np.all(q <= body.q_max)
        assert np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - x_target) < 1e-5
    # Out of reach (the arm spans about 1.2 m): the nearest pose within limits, not an error.
    far = np.array([2.0, 0.5, 0.6])
    q = body.inverse_kinematics(far, body.home_position)
    x_start = np.asarray(body.kinematics_function(body.home_position)[0]).ravel()
    assert np.all(np.isfinite(q)) and np.all(q >= body.q_min) and np.all(q <= body.q_max)
    assert np.linalg.norm(np.asarray(body.kinematics_function(q)[0]).ravel() - far) < np.linalg.norm(x_start - far) - 0.5


def test_yaml_round_trip(tmp_path, rng):
    model = comanip.presets.franka()
    again = comanip.presets.load(comanip.presets.save(model, tmp_path / "franka.yaml"))
    assert again.config() == model.config()
    custom = Panda(damping=np.diag(np.linspace(0.2, 0.4, 7)), armature=np.full(7, 0.05), tcp_offset=[0.0, 0.02, 0.2],
                   hand=False, gravity=True)
    rebuilt = body_from_config(custom.config())
    assert rebuilt.config() == custom.config()
    q = random_configurations(custom, 1, rng)[0]
    for name in ("mass_matrix_function", "gravity_function"):
        np.testing.assert_array_equal(np.asarray(getattr(rebuilt, name)(q)), np.asarray(getattr(custom, name)(q)))
    np.testing.assert_array_equal(np.asarray(rebuilt.kinematics_function(q)[1]), np.asarray(custom.kinematics_function(q)[1]))


@pytest.mark.parametrize("kwargs, argument", [
    ({"damping": np.eye(3)}, "damping"),
    ({"damping": np.nan}, "damping"),
    ({"armature": [0.1] * 6}, "armature"),
    ({"armature": [-0.1] * 7}, "armature"),
    ({"tcp_offset": [0.0, 0.1]}, "tcp_offset"),
    ({"tcp_offset": [0.0, np.inf, 0.1]}, "tcp_offset"),
    ({"hand": "yes"}, "hand"),
    ({"gravity": 1}, "gravity"),
])
def test_bad_constructor_input_names_the_argument(kwargs, argument):
    with pytest.raises(ValueError, match=argument):
        Panda(**kwargs)
