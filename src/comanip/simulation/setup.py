"""What a scenario builds once and reuses for every trial: the world, the person's planner, the robot's
planner or estimator, the settled start, the person's first plan and, for recorded people, the recordings.

Building the solvers takes seconds; a trial then takes a fraction of its simulated time. One
:class:`ScenarioSetup` can serve several runs of the same scenario family (e.g. a near and a far goal):
everything that depends on the goal is computed per run.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from comanip import presets
from comanip.estimation import GoalEstimator
from comanip.model import ReachingModel
from comanip.planning.plan import Plan
from comanip.planning.planner import Planner, SolverOptions
from comanip.recordings.recording import Recording
from comanip.simulation.person import PersonParameters, SimulatedPerson, solve_to_convergence
from comanip.simulation.recorded_person import RECORDING_STRIDE, RecordedPerson, usable_for_reach
from comanip.simulation.scenario import ScenarioSettings, SettledStart, settle
from comanip.simulation.world import CoManipulationWorld


class ScenarioSetup:
    """Shared, lazily built parts of the scenarios for one set of settings (goal and trial count aside)."""

    def __init__(self, settings: ScenarioSettings):
        if not isinstance(settings, ScenarioSettings):
            raise ValueError(f"settings must be a ScenarioSettings, got {type(settings).__name__}")
        self.settings = settings
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

    def recording(self, seed: int) -> Recording:
        """The recording a recorded person with this seed plays (:data:`RECORDING_STRIDE`)."""
        return self.recordings[seed * RECORDING_STRIDE % len(self.recordings)]

    def person(self, start: SettledStart, goal, seed: int, first_plan: Plan | None = None,
               parameters: PersonParameters | None = None) -> SimulatedPerson | RecordedPerson:
        """A person reaching from the settled start for goal (3,), m: the model's person with motor noise from
        seed, or (``parameters.hand_path == "recorded"``) the recording of :meth:`recording` (seed); the load
        they anticipate is the handle's apparent inertia at the start. parameters: None for the settings'."""
        parameters = parameters or self.settings.person
        world = self.world
        world.reset(start.qpos, start.qvel)
        load_inertia = world.handle_inertia(world.observe())
        if parameters.hand_path == "recorded":
            return RecordedPerson(self.recording(seed), parameters, start.position, goal, load_inertia=load_inertia)
        return SimulatedPerson(self.planner, parameters, goal, self.width, np.random.default_rng(seed),
                               first_plan, load_inertia=load_inertia)
