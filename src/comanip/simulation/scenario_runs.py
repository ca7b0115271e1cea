"""A scenario run for several goals, and for sync several robot policies, in one result shape.

:func:`run_scenario` runs a scenario (a name of :data:`comanip.simulation.SCENARIOS`) on each goal's settings,
all sharing one :class:`ScenarioSetup` (the solvers are built once), and answers a :class:`ScenarioResult`
whatever the scenario: per goal a :class:`GoalResult` with the trials (each with its record and metrics), the
wall and simulated time, the summary over trials and, where the scenario has them, its own entries (the
handover's schedule and transition) and every compared policy's trials.

>>> settings = {"near": SyncSettings(goal="near", trials=5), "far": SyncSettings(goal="far", trials=5)}
>>> result = run_scenario("sync", settings, policies=list(POLICIES))
>>> result.summary()["goals"]["near"]["policies"]["continuous"]["goal_error_m"]["median"]
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from comanip.simulation.handover_scenario import HandoverRun, HandoverSettings, HandoverTrial, run_handover
from comanip.simulation.policies import check_policy
from comanip.simulation.policy_comparison import compare_sync_policies, comparison_rows
from comanip.simulation.report import settings_dict, summarise
from comanip.simulation.scenario import ScenarioSettings
from comanip.simulation.setup import ScenarioSetup
from comanip.simulation.sync_scenario import SyncSettings, SyncTrial, run_sync

#: scenario name -> (its settings class, its runner of one goal's trials)
SCENARIOS = {"sync": (SyncSettings, run_sync), "handover": (HandoverSettings, run_handover)}


def scenario(name: str):
    """(settings class, runner) of a scenario by name, or ValueError listing the names."""
    if name not in SCENARIOS:
        raise ValueError(f"scenario must be one of {sorted(SCENARIOS)}, got {name!r}")
    return SCENARIOS[name]


@dataclass
class GoalResult:
    """One goal's trials of a scenario and what its summary, tables and figures need."""

    settings: ScenarioSettings
    trials: list[SyncTrial] | list[HandoverTrial]
    """The trials of the settings' robot, each with its ``record`` and ``metrics``."""
    timing: dict = field(default_factory=dict)
    """wall_s, simulated_s (every policy's trials) and real_time_factor of the goal's run."""
    entries: dict = field(default_factory=dict)
    """The scenario's own summary entries (handover: the schedule, and the transition when there are profiles)."""
    policies: dict[str, list[SyncTrial]] = field(default_factory=dict)
    """sync: every compared policy's trials, the settings' own among them; empty when no policies were compared."""
    profiles: HandoverRun | None = None
    """handover: the run with its profiles over distance to the goal (which need ≥ 2 trials); else None."""

    @property
    def metrics(self) -> list[dict]:
        """The trials' metrics, in trial order."""
        return [trial.metrics for trial in self.trials]

    def summary(self) -> dict:
        """The goal's entry of the summary: its goal (m), every trial's metrics, their summary over trials
        (:func:`comanip.simulation.report.summarise`), the timing, the scenario's own entries and, when
        policies were compared, each policy's summary."""
        out = {"goal_m": list(self.settings.goal), "trials": self.metrics, "summary": summarise(self.metrics),
               "timing": self.timing, **self.entries}
        if self.policies:
            out["policies"] = {name: summarise([trial.metrics for trial in trials]) for name, trials in self.policies.items()}
        return out


@dataclass
class ScenarioResult:
    """Every goal's result of one scenario run, with the setup they shared."""

    scenario: str
    """The scenario's name."""
    setup: ScenarioSetup
    goals: dict[str, GoalResult]
    """goal label -> its result, in the order the goals were given."""
    policies: list[str] | None = None
    """The compared robot policies (sync), or None when only the settings' own ran."""

    @property
    def settings(self) -> ScenarioSettings:
        """The first goal's settings (all goals share every setting but the goal)."""
        return next(iter(self.goals.values())).settings

    def policy_trials(self) -> dict[str, dict[str, list[SyncTrial]]]:
        """{goal label: {policy: trials}} of the compared policies; empty when none were compared."""
        return {label: goal.policies for label, goal in self.goals.items() if goal.policies}

    def policy_rows(self) -> list[dict]:
        """The policy comparison table (:func:`comanip.simulation.policy_comparison.comparison_rows`); empty when
        no policies were compared."""
        return comparison_rows(self.policy_trials()) if self.policies else []

    def summary(self) -> dict:
        """The scenario (and the names of all), the first goal's settings and each goal's summary (:meth:`GoalResult.summary`)."""
        return {"scenario": self.scenario, "scenarios_available": sorted(SCENARIOS), "settings": settings_dict(self.settings),
                "goals": {label: goal.summary() for label, goal in self.goals.items()}}


def run_scenario(name: str, settings_by_goal: dict[str, ScenarioSettings], policies: list[str] | None = None,
                 progress: bool = True, arm_reaches: str | Path | None = None) -> ScenarioResult:
    """Run scenario ``name`` on each goal's settings (labels as given) with one shared setup; ``policies``
    (sync only; names of :data:`comanip.simulation.policies.POLICIES`) runs each of them over the same trials
    and person seeds, the settings' own policy being one of them. Progress bars unless progress=False.
    arm_reaches: the TAT-HUM folder the setup's arm people play (:class:`ScenarioSetup`; a person chosen by name
    says which, :func:`comanip.simulation.people.choose_person`)."""
    scenario(name)
    if not settings_by_goal:
        raise ValueError("settings_by_goal must name at least one goal")
    if policies is not None:
        if name != "sync":
            raise ValueError(f"policies apply to the sync scenario only, got scenario {name!r}")
        policies = [check_policy(policy) for policy in policies]
    setup = ScenarioSetup(next(iter(settings_by_goal.values())), arm_reaches=arm_reaches)
    goals = {}
    for label, settings in settings_by_goal.items():
        begin = time.perf_counter()
        goal = GOAL_RUNNERS[name](label, settings, setup, policies, progress)
        wall = time.perf_counter() - begin
        simulated = settings.trials * setup.duration * (1 if policies is None else len(policies))
        goal.timing = {"wall_s": wall, "simulated_s": simulated, "real_time_factor": simulated / wall}
        goals[label] = goal
    return ScenarioResult(name, setup, goals, policies)


def _sync_goal(label: str, settings: SyncSettings, setup: ScenarioSetup, policies: list[str] | None,
               progress: bool) -> GoalResult:
    if policies is None:
        return GoalResult(settings, run_sync(settings, setup, progress))
    by_policy = compare_sync_policies({label: settings}, policies, setup, progress=progress)[label]
    return GoalResult(settings, by_policy[settings.policy], policies=by_policy)


def _handover_goal(label: str, settings: HandoverSettings, setup: ScenarioSetup, policies: None,
                   progress: bool) -> GoalResult:
    run = run_handover(settings, setup, progress=progress)
    entries = {"schedule": run.schedule.summary()}
    if run.dispersion is not None:
        # the lead at 400 N/m holds the spread down until the release, so this peak lies inside T by
        # construction; the person's own transition is measured with a passive robot
        # (studies/does_the_predicted_handover_match_the_person/measure_handover_transition.py)
        entries["transition"] = {"predicted_distance_m": run.schedule.transition_distance,
                                 "handover_spread_peak_distance_m": run.dispersion.transition_distance}
    return GoalResult(settings, run.trials, entries=entries,
                      profiles=run if run.dispersion is not None else None)


#: scenario name -> how one goal of it runs into a GoalResult
GOAL_RUNNERS = {"sync": _sync_goal, "handover": _handover_goal}
