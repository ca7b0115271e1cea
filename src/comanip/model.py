"""A reaching model: a body plus the motor-control parameters of the paper (Table II, docs/formulation.md §5).

Every field of :class:`ReachingModel` is checked at construction, so a bad value fails before any
CasADi work. Symbols follow the paper: h, H, gamma, nu, kappa, W (``docs/notation.md``).
"""

from __future__ import annotations

import json
from dataclasses import MISSING, dataclass, field, replace

import numpy as np

from comanip.arguments import as_count, as_goal_width, as_in_range, as_nonnegative, as_positive
from comanip.belief.noise import check_noise_form
from comanip.bodies import Body, MuscleActuatedBody, body_from_config
from comanip.objectives.discounting import check_discount_form
from comanip.objectives.reward import check_goal_covariance_form, check_reward_form

#: the slowest activation stage allowed, in time steps h (slower ones make the plant unresponsive and the
#: activation inverse divide by zero)
MAX_ACTIVATION_STEPS = 1000
#: time steps h (s) a model takes: a reach of 0.1-10 s in 10 to 1000 steps lies well inside; far below, the
#: torques a reach needs grow as 1/h² until they overflow (h = 1e-300 s), far above no reach fits in one step
STEP_RANGE_S = (1e-4, 1.0)
#: longest horizon (steps): the solver's dense Newton system has (H·n)² entries, 0.4 GB for the Panda at 1000
MAX_HORIZON_STEPS = 1000


@dataclass(frozen=True)
class ReachingModel:
    """Body and motor-control parameters of one human reaching model."""

    body: Body
    """Arm dynamics and kinematics (point mass or Panda)."""
    h: float
    """Time step (s), within STEP_RANGE_S (1e-4 to 1 s)."""
    H: int
    """Planning horizon (steps), 1 to MAX_HORIZON_STEPS (1000); the plan spans H·h seconds."""
    gamma: float
    """Discount per step of the reward, in (0, 1]; the time cost of the cost–benefit trade-off."""
    nu: float
    """Effort weight on Σ||tau||² (reward units per (N·m)² or N²), ≥ 0."""
    kappa: float
    """Variance of the multiplicative motor-noise entries (dimensionless), ≥ 0; sqrt(kappa) is the
    coefficient of variation of the executed torque."""
    width: float
    """Default goal width w (m), > 0, used when a solve is given no width."""
    noise: str = "isotropic"
    """Noise covariance form: 'isotropic' (default), 'per_channel' or 'rank_one' (docs/formulation.md §2)."""
    goal_covariance: str = "std"
    """How W is built from w: 'std' W = w² I (default), 'cov' W = w I (docs/formulation.md §3), or 'effective'
    W = (2w / effective_k)² I (the goal's full width 2w read as effective_k standard deviations)."""
    effective_k: float = 4.133
    """Standard deviations spanned by the full width 2w under goal_covariance 'effective', > 0; 4.133 is the
    effective-width convention of Fitts studies (2w = 4.133 sigma: 96 % of a 1-D normal inside the target)."""
    reward: str = "gaussian"
    """'gaussian' (default, paper eq. 7): the overlap density of N(mu_x, Sigma_x) and N(g, W), in m^-d;
    'hit': the probability of a hand inside the goal ball of radius w (paper eq. 1), in closed form through
    a flat-topped kernel (comanip.objectives.reward); it saturates once the hand is surely inside."""
    activation: tuple = ()
    """Time constants (s) of the muscle activation stages between command and force, each > 0 (e.g.
    (0.04, 0.04), Todorov 2005); () (default, the paper) applies the command as the force. The motor noise
    enters at the command. See comanip.bodies.muscle."""
    stop_weight: float = 0.0
    """Weight of the terminal stopping cost |J_best(w)| · stop_weight · E||qdot_H||², in (s/m)² or (s/rad)², ≥ 0:
    asks the hand to be still at the end of the horizon. Relative to the best attainable reward |J_best|, so a
    final RMS speed of 1/sqrt(stop_weight) costs as much as the whole reward, whatever the width. Every body
    (for an arm, qdot are the joint speeds in rad/s). 0 (default, the paper): none."""
    joint_velocity_weight: float = 0.0
    """Weight c_v of the running speed cost |J_best(w)| · c_v · (1/H) Σ_{i=1..H} E||qdot_i||², in (s/rad)² for an
    arm's joints or (s/m)² for a point mass, ≥ 0: the body moves no more than the reach needs (an arm's motion in
    its null space, which the reward does not see, costs). A time-averaged RMS speed of 1/sqrt(c_v) costs as much
    as the whole reward. 0 (default, the paper): none; the ``franka_rest`` preset uses it with stop_weight."""
    observation: tuple = ()
    """What the person sees when executing in closed loop (comanip.execution): (position SD in m, velocity
    SD in m/s, delay in s), each finite and ≥ 0; the replans then start from a Kalman estimate made from those
    noisy, delayed observations. () (default): the replans start from the true state. Plans do not use it."""
    discount: str = "exponential"
    """'exponential' gamma^i (default) or 'hyperbolic' 1/(1 + (1/gamma - 1) i)."""
    name: str = "custom"
    """Label used in file names and reports."""
    description: str = field(default="", compare=False)
    """Free text: where the parameters come from."""

    def __post_init__(self):
        if not isinstance(self.body, Body):
            raise ValueError(f"body must be a comanip.bodies.Body, got {type(self.body).__name__}")
        self._attach_activation()
        as_in_range("h", self.h, STEP_RANGE_S, "s, time step")
        slow = [t for t in self.activation if t > MAX_ACTIVATION_STEPS * self.h]
        if slow:
            raise ValueError(f"activation time constants must be ≤ {MAX_ACTIVATION_STEPS} h = {MAX_ACTIVATION_STEPS * self.h:g} s "
                             f"(a slower stage never responds within a plan), got {slow}")
        object.__setattr__(self, "H", as_count("H", self.H, 1, "horizon in steps"))
        if self.H > MAX_HORIZON_STEPS:
            raise ValueError(f"H must be ≤ {MAX_HORIZON_STEPS} (horizon in steps), got {self.H}")
        if not (isinstance(self.gamma, (int, float)) and 0 < self.gamma <= 1):
            raise ValueError(f"gamma must be in (0, 1] (discount per step), got {self.gamma!r}")
        as_nonnegative("nu", self.nu, "reward per N²")
        as_nonnegative("kappa", self.kappa, "dimensionless variance")
        as_goal_width("width", self.width)
        check_noise_form(self.noise)
        check_goal_covariance_form(self.goal_covariance)
        check_reward_form(self.reward)
        check_discount_form(self.discount)
        as_positive("effective_k", self.effective_k, "standard deviations")
        as_nonnegative("stop_weight", self.stop_weight, "(s/m)² or (s/rad)²")
        as_nonnegative("joint_velocity_weight", self.joint_velocity_weight, "(s/m)² or (s/rad)²")
        if not isinstance(self.observation, (tuple, list, np.ndarray)) or len(self.observation) not in (0, 3):
            raise ValueError(f"observation must be () or (position SD m, velocity SD m/s, delay s), got {self.observation!r}")
        object.__setattr__(self, "observation", tuple(as_nonnegative(f"observation[{i}]", v, unit)
                                                      for i, (v, unit) in enumerate(zip(self.observation, ("m", "m/s", "s")))))

    def _attach_activation(self) -> None:
        """Make ``body`` the plant: the bare body, or the bare body behind the activation stages."""
        body = self.body
        if isinstance(body, MuscleActuatedBody) and not self.activation:
            object.__setattr__(self, "activation", body.time_constants)
        bare = body.inner if isinstance(body, MuscleActuatedBody) else body
        try:
            activation = tuple(float(t) for t in self.activation)
        except (TypeError, ValueError):
            raise ValueError(f"activation must be a list of time constants in s, e.g. [0.04, 0.04], got {self.activation!r}") from None
        object.__setattr__(self, "activation", activation)
        object.__setattr__(self, "body", MuscleActuatedBody(bare, activation) if activation else bare)

    @property
    def n(self) -> int:
        """Degrees of freedom of the body."""
        return self.body.n

    @property
    def d(self) -> int:
        """Task-space dimension of the end effector."""
        return self.body.d

    @property
    def state_size(self) -> int:
        """Length of the state s = [q; qdot] (2n), plus n per activation stage."""
        return self.body.state_size

    def full_state(self, state) -> np.ndarray:
        """A state (state_size,) from [q; qdot] (2n,) with the activation stages at zero force, or unchanged."""
        state = np.asarray(state, dtype=float)
        if state.shape == (2 * self.n,) and self.state_size != 2 * self.n:
            return np.concatenate([state, np.zeros(self.state_size - 2 * self.n)])
        return state

    @property
    def M(self):
        """Inertia (n, n): an array for a point mass; for a nonlinear body, a function q -> (n, n) array."""
        if self.body.is_linear:
            return np.asarray(self.body.mass_matrix_function(np.zeros(self.n)))
        return lambda q: np.asarray(self.body.mass_matrix_function(q))

    @property
    def D(self) -> np.ndarray:
        """Damping (n, n)."""
        return self.body.damping

    @property
    def duration(self) -> float:
        """Horizon length H·h (s)."""
        return self.H * self.h

    @property
    def has_velocity_cost(self) -> bool:
        """The objective holds a speed cost (stop_weight or joint_velocity_weight > 0)."""
        return self.stop_weight > 0 or self.joint_velocity_weight > 0

    def replace(self, **changes) -> "ReachingModel":
        """A copy with some fields changed (checked again); ``activation=()`` removes the activation stages."""
        if "activation" in changes and "body" not in changes and isinstance(self.body, MuscleActuatedBody):
            changes["body"] = self.body.inner
        return replace(self, **changes)

    def config(self) -> dict:
        """Plain-data form for YAML; :meth:`from_config` inverts it."""
        return {
            "name": self.name,
            "description": self.description,
            "body": self.body.config(),
            "h": self.h,
            "H": self.H,
            "gamma": self.gamma,
            "nu": self.nu,
            "kappa": self.kappa,
            "width": self.width,
            "noise": self.noise,
            "goal_covariance": self.goal_covariance,
            "effective_k": self.effective_k,
            "reward": self.reward,
            "activation": list(self.activation),
            "stop_weight": self.stop_weight,
            "joint_velocity_weight": self.joint_velocity_weight,
            "observation": list(self.observation),
            "discount": self.discount,
        }

    @classmethod
    def from_config(cls, config: dict) -> "ReachingModel":
        config = dict(config)
        allowed = set(cls.__dataclass_fields__)
        unknown = set(config) - allowed
        if unknown:
            raise ValueError(f"unknown model fields {sorted(unknown)}; allowed: {sorted(allowed)}")
        required = [name for name, f in cls.__dataclass_fields__.items() if f.default is MISSING and f.default_factory is MISSING]
        missing = [name for name in required if name not in config]
        if missing:
            raise ValueError(f"model config lacks the required fields {missing} (required: {required}; the body e.g. "
                             "{type: point_mass, n: 2, mass: 2.0})")
        config["body"] = body_from_config(config["body"])
        return cls(**config)


def config_key(config: dict) -> str:
    """The key of a model given as its ``config()`` dict: its parameters, without the description."""
    config = dict(config)
    config.pop("description", None)
    return json.dumps(config, sort_keys=True)


def model_key(model: ReachingModel) -> str:
    """A key equal for models with equal parameters (two loads of one preset share it)."""
    return config_key(model.config())
