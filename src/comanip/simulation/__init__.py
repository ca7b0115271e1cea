"""Co-manipulation in physics simulation (paper Section VI): a MuJoCo Panda under Cartesian impedance
control carrying an object with a simulated person whose hand follows the motor-control model.

>>> from comanip.simulation import SyncSettings, run_sync
>>> trials = run_sync(SyncSettings(goal="far", trials=5))
>>> [trial.metrics["goal_error_m"] for trial in trials]

Layers: :mod:`panda_model` (the MuJoCo model from the URDF), :mod:`kinematics` (MuJoCo as the controller's
backend), :mod:`world` (plant + controller at 1 kHz), :mod:`person` (the simulated person, at the model's pace or
another) and :mod:`recorded_person` (one whose intended path is a recorded movement), :mod:`people` (a person
chosen by name: ``model``, ``recorded``, ``arm``, a folder of arm reaches, paced), :mod:`scenario` (settings,
workspace, the trial loop), :mod:`sync_scenario` and :mod:`handover_scenario` (paper VI-A, VI-B), :mod:`scenario_runs` (either scenario over
several goals, and sync over several robot policies, into one :class:`ScenarioResult`).
"""

from comanip.simulation.handover_scenario import HandoverRun, HandoverSettings, HandoverTrial, run_handover
from comanip.simulation.people import ChosenPerson, choose_person
from comanip.simulation.person import PersonParameters, SimulatedPerson
from comanip.simulation.recorded_person import RecordedPerson
from comanip.simulation.scenario import NAMED_GOALS, ScenarioSettings, TrialRecord, resolve_goal
from comanip.simulation.scenario_runs import SCENARIOS, GoalResult, ScenarioResult, run_scenario, scenario
from comanip.simulation.setup import ScenarioSetup
from comanip.simulation.sync_scenario import SyncSettings, SyncTrial, run_sync
from comanip.simulation.world import CoManipulationWorld

__all__ = ["ChosenPerson", "CoManipulationWorld", "GoalResult", "HandoverRun", "HandoverSettings", "HandoverTrial", "NAMED_GOALS", "PersonParameters",
           "RecordedPerson", "SCENARIOS", "ScenarioResult", "ScenarioSettings", "ScenarioSetup", "SimulatedPerson", "SyncSettings", "SyncTrial", "TrialRecord",
           "choose_person", "resolve_goal", "run_handover", "run_scenario", "run_sync", "scenario"]
