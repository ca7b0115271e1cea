"""What the two collaborative scenarios share: settings, goals and workspace, the 1 kHz trial loop, records.

Frames and units: the robot base frame (x forward, z up, m), time from the start of the person's reach (s).
A trial first lets the arm, the object and the person's hold settle at the start (so the uncompensated
object weight has already sagged onto the impedances), then runs for ``duration`` seconds. Every step
(1 ms) the person's force and the robot's impedance act on the handle at the TCP.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from comanip.arguments import as_count, as_positive, as_vector
from comanip.control.impedance import ImpedanceGains, RobotState
from comanip.simulation.panda_model import TABLE_HEIGHT
from comanip.simulation.person import PersonParameters, SimulatedPerson
from comanip.simulation.recorded_person import RecordedPerson
from comanip.simulation.rest_trajectory import RestTarget
from comanip.simulation.world import CoManipulationWorld

#: Named goals (m, robot base frame) on a table whose placing height (z = 0.2 m) is fixed and known, as in
#: the paper's synchronisation task. From the ready pose's TCP (0.31, 0, 0.47 after the object's sag) they
#: lie 0.35 m and 0.54 m away; from the table centre (the robot's prior goal) 0.07 m and 0.25 m.
NAMED_GOALS = {"near": (0.45, 0.15, 0.20), "far": (0.45, 0.45, 0.20)}
#: The centre of the table's placing area (m): the robot's prior goal when it must guess the person's.
TABLE_CENTRE = (0.50, 0.20, 0.20)
#: Shoulder (joint 2 axis) position in the base frame, m.
SHOULDER = np.array([0.0, 0.0, 0.333])
#: Wrist centre above the TCP with the hand pointing down (flange 0.107 m + hand 0.1034 m), m.
WRIST_ABOVE_TCP = 0.2104
#: Largest shoulder-to-wrist distance accepted (m). The Panda's links allow about 0.79 m fully stretched, but
#: near that the apparent mass at the handle grows without bound along the arm (48 kg at 0.73 m, against
#: 15–17 kg inside this limit), and a person can hardly steer it.
MAX_WRIST_REACH = 0.70
#: Smallest horizontal distance of a goal from the base axis (m), to keep the object off the robot's base.
MIN_RADIUS = 0.25
#: Lowest TCP height above the table top (m), so the carried box (5 cm high) clears the table.
MIN_HEIGHT = 0.05


def resolve_goal(goal) -> np.ndarray:
    """A goal (3,), m, from a name in :data:`NAMED_GOALS`, a string 'x,y,z' or three numbers; checked against
    the workspace (:func:`check_workspace`)."""
    if isinstance(goal, str):
        if goal in NAMED_GOALS:
            return np.array(NAMED_GOALS[goal])
        try:
            goal = [float(v) for v in goal.replace(",", " ").split()]
        except ValueError:
            raise ValueError(f"goal must be one of {sorted(NAMED_GOALS)} or 'x,y,z' in m, got {goal!r}") from None
    return check_workspace(as_vector("goal", goal, 3, "m, robot base frame"))


def check_workspace(goal: np.ndarray, name: str = "goal") -> np.ndarray:
    """goal (3,), m, if the Panda can carry the object there with the hand pointing down, else ValueError."""
    wrist_reach = float(np.linalg.norm(goal + [0.0, 0.0, WRIST_ABOVE_TCP] - SHOULDER))
    radius = float(np.hypot(goal[0], goal[1]))
    problems = []
    if goal[2] < TABLE_HEIGHT + MIN_HEIGHT:
        problems.append(f"z = {goal[2]:.3f} m is below {TABLE_HEIGHT + MIN_HEIGHT:.2f} m (the table top plus the object)")
    if radius < MIN_RADIUS:
        problems.append(f"its horizontal distance from the base, {radius:.3f} m, is below {MIN_RADIUS} m")
    if wrist_reach > MAX_WRIST_REACH:
        problems.append(f"the wrist would be {wrist_reach:.3f} m from the shoulder, beyond the arm's {MAX_WRIST_REACH} m")
    if problems:
        raise ValueError(f"{name} {np.round(goal, 3).tolist()} m is outside the Panda's workspace: " + "; ".join(problems))
    return goal


def check_trials(trials) -> int:
    return as_count("trials", trials)


@dataclass(frozen=True)
class ScenarioSettings:
    """Inputs shared by the collaborative scenarios (each adds its own)."""

    goal: tuple = NAMED_GOALS["near"]
    """The person's goal (3,), m, robot base frame; a name of :data:`NAMED_GOALS` or 'x,y,z' is accepted."""
    width: float | None = None
    """The person's goal width w (m); None: the Cartesian preset's (0.05 m)."""
    kappa: float | None = None
    """The person's motor-noise variance (dimensionless); None: the Cartesian preset's."""
    trials: int = 5
    """Trials, each with its own motor-noise seed."""
    seed: int = 0
    """Seed of the first trial's noise; trial k uses seed + k."""
    duration: float | None = None
    """Simulated time per trial after the start (s); None: the person's planning horizon H·h, on their own clock
    (× ``person.pace``) when they are slower than the model
    (:meth:`comanip.simulation.setup.ScenarioSetup.trial_duration`)."""
    robot_stiffness: float = 400.0
    """Translational stiffness along the axes the robot leads (N/m)."""
    object_mass: float = 1.5
    """The carried object (kg); its weight is not compensated by the robot."""
    person: PersonParameters = field(default_factory=PersonParameters)
    """The simulated person's arm impedance and replanning."""
    gains: ImpedanceGains = field(default_factory=lambda: ImpedanceGains(translational_stiffness=(0.0, 0.0, 0.0)))
    """Controller gains; the translational stiffness is set by the scenario as it runs."""
    settle_time: float = 1.0
    """Time (s) the person holds still at the start before the reach, for the object's sag to settle."""

    def __post_init__(self):
        object.__setattr__(self, "goal", tuple(resolve_goal(self.goal).tolist()))
        if self.width is not None:
            as_positive("width", self.width, "m")
        if self.kappa is not None and not (isinstance(self.kappa, (int, float)) and np.isfinite(self.kappa) and self.kappa >= 0):
            raise ValueError(f"kappa must be a finite number ≥ 0 (dimensionless variance), got {self.kappa!r}")
        check_trials(self.trials)
        as_count("seed", self.seed, 0)
        if self.duration is not None:
            as_positive("duration", self.duration, "s")
        as_positive("robot_stiffness", self.robot_stiffness, "N/m")
        as_positive("object_mass", self.object_mass, "kg")
        as_positive("settle_time", self.settle_time, "s")
        if not isinstance(self.person, PersonParameters):
            raise ValueError(f"person must be a PersonParameters, got {type(self.person).__name__}")
        if not isinstance(self.gains, ImpedanceGains):
            raise ValueError(f"gains must be an ImpedanceGains, got {type(self.gains).__name__}")


class RobotBehaviour(Protocol):
    """What a scenario's robot does every control step: sets the controller's stiffness, returns its rest motion."""

    goal_estimate: np.ndarray | None
    """Where the robot currently thinks the goal is (3,), m; None while it has no estimate."""

    def command(self, t: float, state: RobotState, handle_force: np.ndarray) -> RestTarget:
        """The rest position and velocity at time t (s) for the arm in ``state``, with the person's force on the
        handle (3,) N as a wrist force sensor reads it."""


@dataclass
class TrialRecord:
    """One trial at the control rate: K samples. Positions m, velocities m/s, forces N, stiffness N/m."""

    t: np.ndarray
    """Time from the start of the reach (K,), s."""
    position: np.ndarray
    """Handle (TCP) position (K, 3)."""
    velocity: np.ndarray
    """Handle velocity (K, 3)."""
    intended_position: np.ndarray
    """The person's intended hand position x_d (K, 3)."""
    intended_velocity: np.ndarray
    """The person's intended hand velocity (K, 3)."""
    rest_position: np.ndarray
    """The impedance controller's rest position (K, 3)."""
    stiffness: np.ndarray
    """The controller's translational stiffness (K, 3)."""
    person_force: np.ndarray
    """The person's force on the handle (K, 3)."""
    robot_force: np.ndarray
    """The impedance's translational force on the handle over the step from each sample (K, 3): K e + D e_dot."""
    goal: np.ndarray
    """The person's goal (3,)."""
    goal_estimate: np.ndarray | None = None
    """The robot's goal estimate at each sample (K, 3), m; NaN rows before it has one (None: never)."""
    qpos: np.ndarray | None = None
    """Joint positions (K, 7), rad: for replays and pictures."""
    replans: int = 0
    """Re-plans the person made."""
    iteration_capped_replans: int = 0
    """The person's re-plans that used all their solver iterations (:attr:`PersonParameters.iterations_per_replan`)
    before the convergence test passed: not a failure, a refinement of the previous plan that was still
    improving when the person acted on it (as intended: a person refines, they do not re-optimise)."""
    wall_time: float = 0.0
    """Wall time of the trial (s), robot solves and the person's re-plans included."""
    replan_time: float = 0.0
    """Wall time of the person's re-plans (s) within wall_time."""

    COLUMNS = ("position", "velocity", "intended_position", "intended_velocity", "rest_position", "stiffness", "person_force",
               "robot_force")

    def save_csv(self, path, every: int = 5) -> None:
        """Write every ``every``-th sample (5 ms at 1 kHz) with one column per axis."""
        header = ["t_s"] + [f"{name}_{axis}" for name in self.COLUMNS for axis in "xyz"]
        table = np.column_stack([self.t] + [getattr(self, name) for name in self.COLUMNS])[::every]
        np.savetxt(path, table, delimiter=",", header=",".join(header), comments="", fmt="%.6g")


@dataclass
class SettledStart:
    """The state every trial starts from: the arm at rest with the object's sag settled."""

    qpos: np.ndarray
    qvel: np.ndarray
    position: np.ndarray
    """Handle position (3,), m."""
    velocity: np.ndarray
    """Handle velocity (3,), m/s (near zero once settled)."""
    hold: np.ndarray
    """Where the person holds their intention (3,), m: the handle's position before the sag."""

    @property
    def state(self) -> np.ndarray:
        """[x; 0] (6,): the handle position at rest, the start the person and the robot plan from."""
        return np.r_[self.position, np.zeros(3)]


def settle(world: CoManipulationWorld, person: PersonParameters, stiffness, duration: float) -> SettledStart:
    """Hold the start pose for duration (s): the robot at the given stiffness (3,) N/m, the person's hand
    impedance around the start, until the object's weight has sagged onto both."""
    world.reset()
    hold = world.observe().position.copy()
    world.controller.translational_stiffness = stiffness
    for _ in range(int(round(duration / world.timestep))):
        state = world.observe()
        world.step(state, person.impedance_force(hold, np.zeros(3), state.position, state.velocity), hold)
    qpos, qvel = world.joint_state()
    world.reset(qpos, qvel)
    state = world.observe()
    return SettledStart(qpos, qvel, state.position.copy(), state.velocity.copy(), hold)


def run_trial(world: CoManipulationWorld, start: SettledStart, person: SimulatedPerson | RecordedPerson, robot: RobotBehaviour,
              duration: float) -> TrialRecord:
    """Simulate one reach of ``duration`` seconds from the settled start, at the world's control rate."""
    begin = time.perf_counter()
    world.reset(start.qpos, start.qvel)
    person.start(start.hold)
    dt = world.timestep
    steps = int(round(duration / dt)) + 1
    record = {name: np.zeros((steps, 3)) for name in TrialRecord.COLUMNS}
    qpos = np.zeros((steps, world.model.nq))
    goal_estimate = np.full((steps, 3), np.nan)
    t = np.arange(steps) * dt
    for k in range(steps):
        state = world.observe()
        position, velocity = state.position, state.velocity
        force = person.force(t[k], position, velocity)
        record["intended_position"][k] = person.intended_position
        record["intended_velocity"][k] = person.intended_velocity
        rest_position, rest_velocity = robot.command(t[k], state, force)
        if robot.goal_estimate is not None:
            goal_estimate[k] = robot.goal_estimate
        record["position"][k], record["velocity"][k] = position, velocity
        record["rest_position"][k] = rest_position
        record["stiffness"][k] = world.controller.translational_stiffness
        record["person_force"][k] = force
        qpos[k] = state.q
        if k < steps - 1:
            world.step(state, force, rest_position, rest_velocity)
        record["robot_force"][k] = world.controller.last_force if k < steps - 1 else record["robot_force"][k - 1]
    replans = person.plans[1:]      # the first plan is made before the trial (shared by trials alike)
    return TrialRecord(t=t, goal=person.goal.copy(), goal_estimate=goal_estimate, qpos=qpos, replans=len(person.plans),
                       iteration_capped_replans=sum(not plan.converged for plan in replans),
                       wall_time=time.perf_counter() - begin,
                       replan_time=sum(plan.solve_time for plan in replans), **record)


def reach_times(record: TrialRecord, tolerance: float) -> np.ndarray:
    """Per axis (3,), s: the first time after which the handle stays within tolerance (m) of the goal
    along that axis until the end of the trial; NaN if it never settles there."""
    inside = np.abs(record.position - record.goal) <= tolerance         # (K, 3)
    times = np.full(3, np.nan)
    for axis in range(3):
        outside = np.flatnonzero(~inside[:, axis])
        if len(outside) == 0:
            times[axis] = record.t[0]
        elif outside[-1] < len(record.t) - 1:
            times[axis] = record.t[outside[-1] + 1]
    return times
