"""The 7-DOF Franka Emika Panda (paper Section V-B): nonlinear M(q), x_ee(q), J(q) from its URDF via adam.

Joint space: q (7,) rad, qdot (7,) rad/s, tau (7,) N·m; task space: x_ee (3,) m in the base frame
``panda_link0``, which is fixed at the origin (z up). The rigid-body algorithms are adam-robotics' (CasADi
backend) on the reduced URDF of :mod:`comanip.bodies.panda_urdf`; adam's floating-base quantities are
evaluated with the base at the identity and their joint blocks kept.
"""

from __future__ import annotations

from functools import cached_property

import casadi as ca
import numpy as np

from comanip.arguments import as_square_matrix, as_vector
from comanip.bodies.body import Body
from comanip.bodies.panda_urdf import ARM_JOINTS, HAND_TCP_OFFSET, TCP_LINK, arm_joint_limits, reduced_panda_urdf

#: Reflected rotor inertia per joint (kg·m²), added to the diagonal of M. Franka publishes none; these are
#: the armature values identified for the Franka Research 3 in MuJoCo Menagerie's ``franka_fr3/fr3.xml``
#: (0.195 on the large drives of joints 1–4, 0.074 on the small drives of joints 5–7), the successor arm
#: with the same two drive sizes. (Menagerie's Panda model uses a uniform, unidentified 0.1.)
PANDA_ARMATURE = (0.195, 0.195, 0.195, 0.195, 0.074, 0.074, 0.074)

#: The Panda's usual "ready" pose (rad), franka_ros' default start: elbow up, flange pointing down,
#: end effector about 0.3 m in front of the base (x) and 0.48 m above it.
READY_POSE = (0.0, -np.pi / 4, 0.0, -3 * np.pi / 4, 0.0, np.pi / 2, np.pi / 4)


class Panda(Body):
    """Franka Emika Panda arm: ``(M_urdf(q) + diag(armature)) qddot + D qdot + G(q) = tau``.

    Stability of the explicit Euler step (docs/formulation.md §10): the URDF has no rotor inertia, its wrist inertia is
    M₇₇ ≈ 0.0067 kg·m², and with D = 0.3 I, h = 0.035 s the velocity factor I − h M⁻¹ D of the step then
    has an eigenvalue near −0.6, so the wrist's mean velocity flips sign every step. The real drives add
    their reflected rotor inertia (:data:`PANDA_ARMATURE`) to the diagonal of M, which bounds M's smallest
    eigenvalue below by min(armature) = 0.074 kg·m², so h·D/M ≤ 0.15 and every eigenvalue lies in (0.85, 1).
    We add the armature rather than integrate the damping implicitly because it is physics the URDF left
    out, and it keeps the docs/formulation.md §2 discretisation (and its A_i, B_i) unchanged for every body.

    Coriolis and centrifugal terms are left out, as in the paper's model (docs/formulation.md §2); gravity G(q) is
    zero by default because the Panda's controller compensates it.

    Args:
        damping: D as a scalar (N·m·s/rad, times the identity) or a (7, 7) matrix. Default 0.3 I (docs/formulation.md §5).
        armature: reflected rotor inertia (7,) kg·m², ≥ 0, added to M's diagonal; zeros give the bare URDF.
        tcp_offset: end-effector point (3,) in the flange frame ``panda_link8``, m. Default: the Franka
            Hand's TCP between the fingertips (0, 0, 0.1034); (0, 0, 0) is the flange itself.
        hand: include the Franka Hand's inertia (0.76 kg with closed fingers); False for a bare flange.
        gravity: include G(q) in the dynamics (False: the controller compensates gravity, docs/formulation.md §2).
    """

    n = 7
    d = 3
    name = "panda"

    def __init__(self, damping: float | np.ndarray = 0.3, armature=PANDA_ARMATURE, tcp_offset=HAND_TCP_OFFSET,
                 hand: bool = True, gravity: bool = False):
        self.damping = as_square_matrix("damping", damping, self.n, "N·m·s/rad")
        self.armature = as_vector("armature", armature, self.n, "reflected rotor inertia per joint, kg·m²")
        if np.any(self.armature < 0):
            raise ValueError(f"armature must be ≥ 0 (kg·m²), got {self.armature.tolist()}")
        self.tcp_offset = as_vector("tcp_offset", tcp_offset, 3, "end-effector point in the flange frame, m")
        for flag, value in (("hand", hand), ("gravity", gravity)):
            if not isinstance(value, (bool, np.bool_)):
                raise ValueError(f"{flag} must be True or False, got {value!r}")
        self.hand, self.include_gravity = bool(hand), bool(gravity)
        self.urdf = reduced_panda_urdf(self.hand, self.tcp_offset)
        self.joint_limits = arm_joint_limits(self.urdf)  # position (rad), speed (rad/s), torque (N·m)

    @cached_property
    def _rigid_body(self) -> dict[str, ca.Function]:
        """adam's M, x_ee, J, G as CasADi functions of q (7,) alone, built once on first use (under 1 s)."""
        from comanip.extras import require

        adam_casadi = require("adam.casadi", "panda")  # heavy import, paid only when the Panda is used
        kindyn = adam_casadi.KinDynComputations(self.urdf, list(ARM_JOINTS))
        base = ca.DM.eye(4)
        q = ca.SX.sym("q", self.n)
        expressions = {
            "M": kindyn.mass_matrix_fun()(base, q)[6:, 6:] + ca.diag(self.armature),
            "x_ee": kindyn.forward_kinematics_fun(TCP_LINK)(base, q)[:3, 3],
            "J": kindyn.jacobian_fun(TCP_LINK)(base, q)[:3, 6:],
            "G": kindyn.gravity_term_fun()(base, q)[6:],
        }
        return {key: ca.Function(key, [q], [value], ["q"], [key]) for key, value in expressions.items()}

    def mass_matrix(self, q):
        return self._rigid_body["M"](q)

    def end_effector(self, q):
        return self._rigid_body["x_ee"](q)

    def jacobian(self, q):
        return self._rigid_body["J"](q)

    def gravity(self, q):
        return self._rigid_body["G"](q) if self.include_gravity else super().gravity(q)

    @cached_property
    def _inverse_kinematics_solver(self) -> ca.Function:
        """IPOPT on min ½||x_ee(q) - x||² + ½ lambda ||q - q_init||² within [q_min, q_max]; p = [x; q_init]."""
        q, x, q_init = ca.SX.sym("q", self.n), ca.SX.sym("x", self.d), ca.SX.sym("q_init", self.n)
        # lambda (m²/rad²) only picks, among the redundant arm's many solutions, the one nearest q_init; it
        # biases the reached point by about lambda·|q - q_init| / sigma_min(J)² (~1e-7 m), removed by the polish.
        objective = 0.5 * ca.sumsqr(self.end_effector(q) - x) + 0.5e-6 * ca.sumsqr(q - q_init)
        return ca.nlpsol("panda_ik", "ipopt", {"x": q, "p": ca.vertcat(x, q_init), "f": objective},
                         {"ipopt": {"print_level": 0, "sb": "yes", "tol": 1e-12, "max_iter": 200},
                          "print_time": False, "error_on_fail": False})

    def inverse_kinematics(self, x: np.ndarray, q_init: np.ndarray, iterations: int = 100) -> np.ndarray:
        """Joint position (n,) within the joint limits whose end effector is nearest x (3,), m.

        The base class's damped least squares, clipped at the limits, can stall against a limit (about 1
        in 30 random reachable targets did); a bound-constrained IPOPT solve does not, and a few
        least-squares steps from its answer then remove the bias of its tie-breaking term. Out of reach,
        the answer is the nearest reachable point within the limits.
        """
        q_init = self.clip_to_limits(as_vector("q_init", q_init, self.n, "joint position, rad"))
        x = as_vector("x", x, self.d, "end-effector position, m")
        result = self._inverse_kinematics_solver(x0=q_init, p=np.concatenate([x, q_init]), lbx=self.q_min, ubx=self.q_max)
        q_nearest = self.clip_to_limits(np.asarray(result["x"]).ravel())  # IPOPT relaxes bounds by ~1e-8
        q_polished = self.least_squares_inverse_kinematics(x, q_nearest, iterations)
        # Out of reach the least-squares steps leap about near the stretched-out singularity: keep the better.
        return min((q_polished, q_nearest), key=lambda q: np.linalg.norm(np.asarray(self.kinematics_function(q)[0]).ravel() - x))

    @property
    def home_position(self) -> np.ndarray:
        return np.array(READY_POSE)

    def config(self) -> dict:
        return {"type": "panda", "damping": self.damping.tolist(), "armature": self.armature.tolist(),
                "tcp_offset": self.tcp_offset.tolist(), "hand": self.hand, "gravity": self.include_gravity}
