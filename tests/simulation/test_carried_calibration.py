"""An estimating robot carries what it learned of the person from trial to trial of a run (SyncSettings.carry_calibration)."""

import math

import pytest

from comanip.simulation import ScenarioSetup, SyncSettings, run_sync
from comanip.simulation.people import choose_person

pytest.importorskip("mujoco", reason="the scenario needs the 'sim' extra")


@pytest.fixture(scope="module")
def setup():
    """The shipped arm reaches played 2.5 times slower (they come to rest within the trial: a reach to learn from)."""
    person = choose_person("arm-x2.5")
    return ScenarioSetup(SyncSettings(person=person.parameters), arm_reaches=person.arm_reaches)


def _run(setup, carry: bool, policy: str = "forecast", trials: int = 2):
    settings = SyncSettings(goal="near", trials=trials, policy=policy, person=setup.settings.person, online_preset="arm",
                            carry_calibration=carry)
    return run_sync(settings, setup, progress=False)


def _same(a: dict, b: dict) -> bool:
    """The same measures (NaN equal to NaN), the estimates' solve times (wall clock) aside."""
    keys = [key for key in a if key != "estimate_time_s"]
    return a.keys() == b.keys() and all(a[key] == b[key] or (isinstance(a[key], float) and math.isnan(a[key])
                                                             and math.isnan(b[key])) for key in keys)


def test_the_second_trial_starts_with_what_the_first_taught_and_without_it_when_off(setup):
    carried, fresh = _run(setup, True), _run(setup, False)
    assert carried[0].metrics["calibration_reaches"] == 0 and carried[1].metrics["calibration_reaches"] == 1
    assert carried[1].metrics["calibration_amplitude"] != 1.0 and carried[1].metrics["calibration_pace"] != 1.0
    assert all(trial.metrics["calibration_reaches"] == 0 and trial.metrics["calibration_amplitude"] == 1.0
               for trial in fresh)
    assert _same(carried[0].metrics, fresh[0].metrics)                  # the first trial meets a person not seen yet
    assert carried[1].metrics["goal_error_mean_m"] != fresh[1].metrics["goal_error_mean_m"]   # ... the second does not


def test_a_carried_run_is_the_same_for_the_same_seed(setup):
    first, again = _run(setup, True), _run(setup, True)
    assert all(_same(a.metrics, b.metrics) for a, b in zip(first, again))


def test_robots_that_do_not_estimate_online_learn_nothing(setup):
    trial, = _run(setup, True, policy="one-shot", trials=1)
    assert not any(key.startswith("calibration_") for key in trial.metrics)


def test_carry_calibration_must_be_true_or_false():
    with pytest.raises(ValueError, match="carry_calibration must be True or False"):
        SyncSettings(carry_calibration="yes")
