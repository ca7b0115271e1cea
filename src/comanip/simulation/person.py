"""A simulated person holding the handle: the paper's motor-control model drives an arm impedance.

The person's *intended* hand motion x_d(t) is the state of their internal model, the reaching model's point
mass (the Cartesian preset, 2 kg) in the model's own discrete time (docs/formulation.md §2, forward Euler with step h),
driven by the commands they plan, executed with signal-dependent motor noise (I + E) tau:

    v_{j+1} = v_j + h M_p^-1 ((I + E_j) tau_j - D_p v_j),   x_{j+1} = x_j + h v_j

and between the steps x_d(t) follows a C² cubic spline through the positions x_j, leaving with the
intention's current velocity. No smooth curve can match both the Euler positions and velocities (x_j moves
with v_j over the whole step, so a smooth velocity through the step's ends must ripple); the positions are
kept because a goal estimator reading the hand is far more sensitive to them: on a 0.35 m reach, a hand
h v / 2 ≈ 3 mm ahead of the model's position 0.165 s in (a finely integrated point mass) moves the estimate
by 0.24 m, a velocity lagging the model's by h a / 2 only by 3 cm.

Every ``replan_interval`` seconds the person re-plans a reach to their goal (:class:`comanip.Planner`,
warm-started with the previous plan shifted) from s = [x; v_j]: the hand position x they see, and the
velocity of their own intended motion, the model's v_j (their efference copy). The force on the handle is the arm's
impedance around the intention, its only force path:

    F = K_h (x_d - x) + D_h (xdot_d - xdot)

Why this feedback closes a stable loop: a plan from the seen position moves the intention by the remaining
distance to the goal, so x_d ends at the goal plus the current intention-hand offset, which is exactly what
the impedance needs to hold the hand on the goal against a load (the object's weight) or a robot spring.
Planning from the *measured* hand velocity instead, while the commands drive the intention, counts the
velocity error twice (once in the plan, once in D_h) and the loop oscillates with growing amplitude.

A person who is not the model's pace (``PersonParameters.pace`` = p ≠ 1) runs that whole internal model on
their own clock s = t / p: the same plans, commands, noise and re-plans every ``replan_interval`` of s (so every
p · replan_interval seconds), their intention x_d(t) = x_model(t / p) with velocity x_model'(t / p) / p; the
efference copy stays in the model's units, so a plan from it is the model's plan. Past their planning horizon
(s > H·h) the reach is over and the person holds the intention where it ended. A person whose intended hand
path is a recorded movement is :class:`comanip.simulation.recorded_person.RecordedPerson`.

On the axes the person does not lead (``PersonParameters.led_axes``; the paper's task: the height) the intention and
the force are the following arm's (:mod:`comanip.simulation.following_arm`), whatever the plan does there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.interpolate import CubicSpline

from comanip.arguments import as_count, as_matrix, as_positive, as_vector
from comanip.belief.noise import sample_torque_error
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner
from comanip.simulation.following_arm import FollowedAxes, FollowingArm


#: The sources of a simulated person's intended hand motion (:attr:`PersonParameters.hand_path`).
HAND_PATHS = ("model", "recorded", "recorded-arm")


@dataclass(frozen=True)
class PersonParameters:
    """The simulated person's arm impedance and how often they re-plan."""

    stiffness: float = 800.0
    """Hand endpoint stiffness K_h (N/m), isotropic. Arms hold roughly 300–1500 N/m, the upper part when
    co-contracting to stabilise a load (Mussa-Ivaldi et al. 1985; Burdet et al. 2001)."""
    damping: float = 120.0
    """Hand endpoint damping D_h (N·s/m). The handle is heavy: the arm holding the object's attitude has an
    apparent mass of about 5–14 kg at the TCP, plus the 1.5 kg object; 120 N·s/m damps the hand on a
    15 kg load at ratio 0.55, where arm-only values (10–50 N·s/m, Tsuji et al. 1995) would leave it ringing
    at ~1 Hz for seconds."""
    replan_interval: float = 0.22
    """Time between re-plans (s) on the person's own clock (pace × this in the simulation's time), a whole
    number of the model's steps h (4 × 0.055 s): visual feedback reaches the motor plan intermittently, about
    every 0.2–0.3 s (Loram et al. 2011)."""
    iterations_per_replan: int = 4
    """Solver iterations per warm-started re-plan: the person refines the previous plan, not a fresh optimum."""
    motor_noise: bool = True
    """Execute the commands with the model's signal-dependent noise (False: exactly as planned)."""
    anticipates_inertia: bool = True
    """Add the feedforward force M_load xddot_d that the handle's inertia needs to follow the intention: a
    practised person's internal model of the object they move (Flanagan & Wing 1997). Without it a heavy
    handle lags the intention by M_load xddot_d / K_h (about 40 % of the distance 0.2 s into a reach)."""
    pace: float = 1.0
    """The person's duration relative to their intended motion's (dimensionless): that motion played over pace
    times its duration, positions unchanged, times × pace, velocities ÷ pace (module docstring). 1: the model's
    own pace (or the recording's); 0.7: 30 % faster; 1.3: 30 % slower."""
    led_axes: tuple = (0, 1, 2)
    """The axes the person's intention covers (indices of x, y, z). On the others a partner leads and the person's
    arm follows (:mod:`comanip.simulation.following_arm`): (0, 1) is the paper's synchronisation task, the person
    leading the horizontal motion and leaving the height to the robot; (0, 1, 2): the person intends every axis."""
    following: FollowingArm = FollowingArm()
    """The arm's impedance on the axes the person does not lead."""
    hand_path: Literal["model", "recorded", "recorded-arm"] = "model"
    """Where the intended hand motion comes from: ``"model"``, the reaching model's plan, re-planned every
    ``replan_interval``; ``"recorded"``, a recorded person's mouse movement (development split of the cursory
    recordings, ``pip install -e ".[data]"``) scaled and turned onto the reach and played at its recorded timing
    (:mod:`comanip.simulation.recorded_person`), with the same arm impedance and no re-planning;
    ``"recorded-arm"``, the same with a motion-capture arm reach in 3-D (the scenario setup's ``arm_reaches``
    folder)."""

    def __post_init__(self):
        as_positive("stiffness", self.stiffness, "N/m")
        as_positive("damping", self.damping, "N·s/m")
        as_positive("replan_interval", self.replan_interval, "s")
        as_count("iterations_per_replan", self.iterations_per_replan)
        as_positive("pace", self.pace, "dimensionless")
        if self.hand_path not in HAND_PATHS:
            raise ValueError(f"hand_path must be one of {HAND_PATHS}, got {self.hand_path!r}")
        led = tuple(self.led_axes) if isinstance(self.led_axes, (tuple, list)) else None
        if not led or len(set(led)) != len(led) or not all(a in (0, 1, 2) for a in led):
            raise ValueError(f"led_axes must be distinct axis indices among 0, 1, 2 (x, y, z), at least one, got {self.led_axes!r}")
        object.__setattr__(self, "led_axes", tuple(sorted(led)))
        if not isinstance(self.following, FollowingArm):
            raise ValueError(f"following must be a FollowingArm, got {type(self.following).__name__}")

    @property
    def followed_axes(self) -> tuple:
        """The axes a partner leads: those not in :attr:`led_axes`."""
        return tuple(a for a in range(3) if a not in self.led_axes)

    def followed(self) -> FollowedAxes:
        """The following arm of one reach on :attr:`followed_axes`."""
        return FollowedAxes(self.followed_axes, self.following, self.impedance_force)

    def impedance_force(self, intended_position, intended_velocity, position, velocity) -> np.ndarray:
        """F = K_h (x_d - x) + D_h (xdot_d - xdot), (3,) N, from intended and actual hand states (3,) m, m/s."""
        return self.stiffness * (intended_position - position) + self.damping * (intended_velocity - velocity)


def solve_to_convergence(planner: Planner, start, goal, width: float, warm_start=None, rounds: int = 50) -> Plan:
    """Solve with a planner whose iteration limit is small, continuing from each result until it converges.

    Lets one planner (built once, with a per-replan iteration cap) also deliver fully converged plans.
    Returns the last plan (check ``plan.converged`` and ``plan.success``); at most ``rounds`` solves.
    """
    plan = planner.solve(start, goal, width, warm_start=warm_start)
    for _ in range(rounds - 1):
        if plan.converged:
            break
        plan = planner.solve(start, goal, width, warm_start=plan)
    return plan


class SimulatedPerson:
    """One person reaching for one goal while holding the handle.

    Args:
        planner: a Planner for a point-mass model in task space (the Cartesian preset); its iteration
            limit is the per-replan effort (see :attr:`PersonParameters.iterations_per_replan`).
        parameters: arm impedance and replanning.
        goal: the person's goal (3,), m; width: its width w (m).
        rng: generator of the motor noise.
        first_plan: a converged plan from the start state, shared by trials that start alike (computed
            here when None).
        load_inertia: M_load (3, 3), kg: the apparent inertia of what the hand moves, used for the
            feedforward when ``parameters.anticipates_inertia``.
    """

    def __init__(self, planner: Planner, parameters: PersonParameters, goal, width: float,
                 rng: np.random.Generator, first_plan: Plan | None = None, load_inertia=None):
        body = planner.model.body
        if not body.is_linear or body.n != 3:
            raise ValueError(f"the person's planner needs a 3-D point-mass model (the Cartesian preset), got {planner.model.name!r}")
        steps = parameters.replan_interval / planner.model.h
        if abs(steps - round(steps)) > 1e-6 or round(steps) < 1:
            raise ValueError(f"replan_interval must be a whole multiple of the model's step h = {planner.model.h} s, "
                             f"got {parameters.replan_interval} s")
        self.planner, self.parameters = planner, parameters
        self.goal = as_vector("goal", goal, 3, "m")
        self.width = as_positive("width", width, "m")
        self.rng = rng
        self.first_plan = first_plan
        self._steps_per_replan = int(round(steps))
        self._inertia = np.asarray(body.mass_matrix_function(np.zeros(3)))
        self._inverse_inertia = np.linalg.inv(self._inertia)
        self._damping = body.damping
        self._load_inertia = np.zeros((3, 3))
        if parameters.anticipates_inertia:
            if load_inertia is None:
                raise ValueError("load_inertia (3, 3) kg is needed when the person anticipates the load's inertia")
            self._load_inertia = as_matrix("load_inertia", load_inertia, (3, 3), "kg")
        self.plans: list[Plan] = []
        self.replan_times: list[float] = []
        self._followed = parameters.followed()

    def start(self, intended_position, t: float = 0.0) -> None:
        """Begin the reach at time t (s), the intention at rest at intended_position (3,) m (where the person
        held the hand before the reach; the hand itself may sag below it under a load)."""
        self.intended_position = np.array(intended_position, dtype=float)
        self.intended_velocity = np.zeros(3)
        self._clock_start = t
        self._model_velocity = np.zeros(3)    # the Euler model's velocity at the current step (model time)
        self._model_rate = np.zeros(3)        # dx_d/ds, the intention's velocity on the person's clock s
        self._next_replan = 0.0               # on the person's clock s (module docstring)
        self._plan = None
        self._followed.start(self.intended_position)

    def force(self, t: float, position, velocity) -> np.ndarray:
        """Force on the handle (3,), N, with the hand at position (3,) m, velocity (3,) m/s at time t (s);
        sets the intention (``intended_position``, ``intended_velocity``) to time t."""
        pace = self.parameters.pace
        s = (t - self._clock_start) / pace
        if s > self.planner.model.duration + 1e-9:
            # past their planning horizon the person's reach is over: they hold the intention where it ended
            # (re-plans from a hand at rest on the goal long after the reach can leave it)
            self.intended_velocity = np.zeros(3)
            force = self.parameters.impedance_force(self.intended_position, self.intended_velocity, position, velocity)
        else:
            force = self._intended_force(s, t, position, velocity)
        self._followed.apply(t, position, velocity, self.intended_position, self.intended_velocity, force)
        return force

    def _intended_force(self, s: float, t: float, position, velocity) -> np.ndarray:
        """The force (3,) N of the arm's impedance around the intention at the person's clock s (s) = time t (s),
        with the load's feedforward; sets the intention."""
        pace = self.parameters.pace
        if s >= self._next_replan - 1e-9:
            self._replan(s, t, position)
        h = self.planner.model.h
        j = min(int((s - self._plan_time) / h + 1e-9), len(self._spline) - 1)
        tau = s - self._plan_time - j * h
        # on step j, x = c3 tau³ + c2 tau² + c1 tau + c0: position, velocity, acceleration (3, 3) at once, per s
        self.intended_position, self._model_rate, acceleration = np.array(
            [[tau**3, tau**2, tau, 1.0], [3 * tau**2, 2 * tau, 1.0, 0.0], [6 * tau, 2.0, 0.0, 0.0]]) @ self._spline[j]
        self.intended_velocity = self._model_rate / pace
        return self.parameters.impedance_force(self.intended_position, self.intended_velocity, position, velocity) \
            + self._load_inertia @ acceleration / pace**2

    def _replan(self, s: float, t: float, position) -> None:
        """Re-plan at the person's clock s (s) = time t (s), from the hand's position (3,) m."""
        start = np.r_[position, self._model_velocity]
        if self._plan is None:
            self._plan = self.first_plan if self.first_plan is not None else solve_to_convergence(
                self.planner, start, self.goal, self.width)
        else:
            shift = min(self._steps_per_replan, self.planner.model.H - 1)
            warm = np.vstack([self._plan.torque[shift:], np.repeat(self._plan.torque[-1:], shift, axis=0)])
            self._plan = self.planner.solve(start, self.goal, self.width, warm_start=warm)
        self.plans.append(self._plan)
        self.replan_times.append(t)
        commands = self._plan.torque[: self._steps_per_replan]
        model = self.planner.model
        noise = sample_torque_error(commands, model.kappa, model.noise, self.rng) if self.parameters.motor_noise else 0.0
        # the intention's positions at the coming steps: the model's Euler steps under the executed commands
        # (then two more of the plan, so the spline's free end lies beyond the interval), from where the
        # intention is: its offset from the hand carries over
        x, v = [self.intended_position], [self._model_velocity]
        for command in np.vstack([commands + noise, self._plan.torque[len(commands) : len(commands) + 2]]):
            x.append(x[-1] + model.h * v[-1])
            v.append(v[-1] + model.h * self._inverse_inertia @ (command - self._damping @ v[-1]))
        spline = CubicSpline(model.h * np.arange(len(x)), np.array(x), bc_type=((1, self._model_rate), "not-a-knot"))
        self._spline = spline.c[:, : len(commands)].transpose(1, 0, 2)  # (steps, 4, 3) coefficients per step
        self._model_velocity = v[len(commands)]
        self._plan_time = s
        self._next_replan = s + self.parameters.replan_interval
