"""What a scenario builds once and reuses for every trial: the world, the person's planner, the robot's
planner or estimator, the settled start, the person's first plan and, for recorded people, the recordings
(mouse movements of the cursory development split, or motion-capture arm reaches from a folder of them: TAT-HUM's
layout or Vicon Nexus exports).

Building the solvers takes seconds; a trial then takes a fraction of its simulated time. One
:class:`ScenarioSetup` can serve several runs of the same scenario family (e.g. a near and a far goal):
everything that depends on the goal is computed per run.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path

import numpy as np

from comanip import presets
from comanip.estimation import GoalEstimator
from comanip.model import ReachingModel
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner, SolverOptions
from comanip.recordings.recording import Recording
from comanip.simulation.people import arm_reach_layout
from comanip.simulation.person import PersonParameters, SimulatedPerson, solve_to_convergence
from comanip.simulation.recorded_person import RECORDING_STRIDE, RecordedPerson, surface_normal, usable_for_reach
from comanip.simulation.scenario import ScenarioSettings, SettledStart, settle
from comanip.simulation.world import CoManipulationWorld


class ScenarioSetup:
    """Shared, lazily built parts of the scenarios for one set of settings (goal and trial count aside).

    arm_reaches: a folder of motion-capture arm reaches (:func:`comanip.simulation.people.arm_reach_layout`: a
    TAT-HUM data folder, :func:`comanip.recordings.load_tathum`, or Vicon Nexus exports of one person or of one
    sub-folder per person, :func:`comanip.recordings.load_nexus_trajectories`, the fingertip of the arm that
    reached), the intended paths of people with ``hand_path="recorded-arm"``; None: no such people.
    """

    def __init__(self, settings: ScenarioSettings, arm_reaches: str | Path | None = None):
        if not isinstance(settings, ScenarioSettings):
            raise ValueError(f"settings must be a ScenarioSettings, got {type(settings).__name__}")
        self.settings = settings
        self.arm_reaches = None if arm_reaches is None else Path(arm_reaches)
        self._online_models: dict[str, ReachingModel] = {}
        base = presets.cartesian()
        self.model: ReachingModel = base if settings.kappa is None else base.replace(kappa=settings.kappa)
        self.width = self.model.width if settings.width is None else float(settings.width)
        self.duration = self.model.duration if settings.duration is None else float(settings.duration)
        self._starts: dict[tuple, SettledStart] = {}
        self._first_plans: dict[tuple, Plan] = {}

    @cached_property
    def world(self) -> CoManipulationWorld:
        s = self.settings
        return CoManipulationWorld(s.gains, object_mass=s.object_mass)

    @cached_property
    def planner(self) -> Planner:
        """The Cartesian preset's planner, limited to the person's iterations per re-plan; the robot's
        plans continue from each result until they converge (:func:`solve_to_convergence`)."""
        return Planner(self.model, SolverOptions(max_iterations=self.settings.person.iterations_per_replan))

    @cached_property
    def estimator(self) -> GoalEstimator:
        """The robot's goal estimator (Cartesian preset)."""
        return GoalEstimator(self.model)

    def trial_duration(self, person: PersonParameters) -> float:
        """Simulated time per trial (s) with this person: the settings' duration when given, else the person's
        planning horizon on their own clock, H·h × pace, but never less than H·h (a faster person's reach
        ends sooner, the handle's settling does not)."""
        if self.settings.duration is not None:
            return self.duration
        return self.duration * max(1.0, person.pace)

    def settled_start(self, stiffness) -> SettledStart:
        """The start with the object's sag settled, with the robot at translational stiffness (3,) N/m."""
        key = tuple(np.asarray(stiffness, dtype=float).tolist())
        if key not in self._starts:
            self._starts[key] = settle(self.world, self.settings.person, stiffness, self.settings.settle_time)
        return self._starts[key]

    def person_first_plan(self, start: SettledStart, goal) -> Plan:
        """The person's converged plan from the settled start to the goal (the same for every trial)."""
        key = tuple(start.state.tolist()) + tuple(np.asarray(goal, dtype=float).tolist())
        if key not in self._first_plans:
            self._first_plans[key] = solve_to_convergence(self.planner, start.state, goal, self.width)
        return self._first_plans[key]

    @cached_property
    def recordings(self) -> list[Recording]:
        """The development split's recorded movements that play as a reach (:func:`usable_for_reach`), in file
        order: the intended paths of recorded people (needs ``pip install -e ".[data]"``)."""
        from comanip.recordings import load_cursory

        return [recording for recording in load_cursory("development") if usable_for_reach(recording)]

    @cached_property
    def arm_recordings(self) -> list[Recording]:
        """The arm reaches of the ``arm_reaches`` folder that play as a reach (:func:`usable_for_reach`), by
        participant and trial (TAT-HUM) or by file (Nexus exports): the intended paths of people with
        ``hand_path="recorded-arm"``."""
        if self.arm_reaches is None:
            raise ValueError('people with hand_path="recorded-arm" need the setup\'s arm_reaches folder (TAT-HUM layout '
                             'or Vicon Nexus exports)')
        from comanip.recordings import load_nexus_trajectories, load_tathum

        load = load_tathum if arm_reach_layout(self.arm_reaches) == "tathum" else load_nexus_trajectories
        recordings = [trial.recording() for trial in load(self.arm_reaches)]
        usable = [recording for recording in recordings if usable_for_reach(recording)]
        if not usable:
            raise ValueError(f"none of the {len(recordings)} arm reaches in {str(self.arm_reaches)!r} plays as a reach "
                             f"(usable_for_reach: from rest, fairly straight, at least 0.1 m, at most 2 s)")
        return usable

    @cached_property
    def arm_up(self) -> np.ndarray:
        """The arm reaches' upward direction (3,) in their tracker's frame (:func:`surface_normal`)."""
        return surface_normal(self.arm_recordings)

    def recording(self, seed: int, hand_path: str = "recorded") -> Recording:
        """The recording a recorded person (``hand_path`` "recorded" or "recorded-arm") with this seed plays:
        number (seed · :data:`RECORDING_STRIDE`) mod N of the N usable ones."""
        recordings = self.arm_recordings if hand_path == "recorded-arm" else self.recordings
        return recordings[seed * RECORDING_STRIDE % len(recordings)]

    def online_model(self, preset: str | None) -> ReachingModel:
        """The reaching model of an online goal estimator: the preset of that name (:mod:`comanip.presets`),
        built once; None: the scenario's model."""
        if preset is None:
            return self.model
        if preset not in self._online_models:
            self._online_models[preset] = presets.load(preset)
        return self._online_models[preset]

    def person(self, start: SettledStart, goal, seed: int, first_plan: Plan | None = None,
               parameters: PersonParameters | None = None) -> SimulatedPerson | RecordedPerson:
        """A person reaching from the settled start for goal (3,), m: the model's person with motor noise from
        seed, or (``parameters.hand_path`` "recorded" or "recorded-arm") the recording of :meth:`recording`; the load
        they anticipate is the handle's apparent inertia at the start. parameters: None for the settings'."""
        parameters = parameters or self.settings.person
        world = self.world
        world.reset(start.qpos, start.qvel)
        load_inertia = world.handle_inertia(world.observe())
        if parameters.hand_path == "recorded":
            return RecordedPerson(self.recording(seed), parameters, start.position, goal, load_inertia=load_inertia)
        if parameters.hand_path == "recorded-arm":
            return RecordedPerson(self.recording(seed, "recorded-arm"), parameters, start.position, goal,
                                  load_inertia=load_inertia, up=self.arm_up)
        return SimulatedPerson(self.planner, parameters, goal, self.width, np.random.default_rng(seed),
                               first_plan, load_inertia=load_inertia)
