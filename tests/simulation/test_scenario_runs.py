"""Both scenarios run over several goals into one result shape (run_scenario, ScenarioResult)."""

import pytest

from comanip.simulation import HandoverSettings, ScenarioResult, SyncSettings, run_scenario

DURATION = 1.0     # s per sync trial: enough for the robot's first prediction (t_o = 0.2 s), short for a test


@pytest.mark.slow
def test_sync_and_handover_answer_the_same_shape():
    sync = run_scenario("sync", {"near": SyncSettings(goal="near", trials=2, duration=DURATION),
                                 "far": SyncSettings(goal="far", trials=2, duration=DURATION)}, progress=False)
    handover = run_scenario("handover", {"near": HandoverSettings(goal="near", trials=2)}, progress=False)
    for result, labels in ((sync, ["near", "far"]), (handover, ["near"])):
        assert isinstance(result, ScenarioResult) and list(result.goals) == labels
        summary = result.summary()
        assert list(summary["goals"]) == labels
        for label, goal in result.goals.items():
            duration = result.setup.duration
            assert len(goal.trials) == 2 and all(trial.record.t[-1] == pytest.approx(duration) for trial in goal.trials)
            assert summary["goals"][label]["trials"] == goal.metrics
            assert summary["goals"][label]["goal_m"] == list(goal.settings.goal)
            assert goal.timing["simulated_s"] == pytest.approx(2 * duration)
    assert all(not goal.entries and goal.profiles is None and not goal.policies for goal in sync.goals.values())
    near = handover.goals["near"]
    assert set(near.entries) == {"schedule", "transition"} and near.profiles is not None     # 2 trials: profiles
    assert sync.policy_rows() == [] and sync.policy_trials() == {}


@pytest.mark.slow
def test_compared_policies_share_the_trials_and_count_in_the_timing():
    policies = ["passive", "one-shot"]
    result = run_scenario("sync", {"near": SyncSettings(goal="near", trials=1, duration=DURATION, policy="one-shot")},
                          policies=policies, progress=False)
    goal = result.goals["near"]
    assert list(goal.policies) == policies and goal.trials is goal.policies["one-shot"]
    assert goal.timing["simulated_s"] == pytest.approx(len(policies) * DURATION)
    assert [(row["goal"], row["policy"]) for row in result.policy_rows()] == [("near", "passive"), ("near", "one-shot")]
    assert set(result.summary()["goals"]["near"]["policies"]) == set(policies)


@pytest.mark.slow
def test_the_comparison_figure_of_a_policy_that_estimates_nothing_draws_without_warnings(tmp_path):
    """The passive robot makes no goal estimates: its comparison figure says so instead of an empty legend."""
    import warnings

    from comanip.plots.policy_comparison_figure import plot_policy_comparison

    result = run_scenario("sync", {"near": SyncSettings(goal="near", trials=1, duration=DURATION, policy="passive")},
                          policies=["passive"], progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = plot_policy_comparison(result.policy_trials(), tmp_path / "policies.png")
    assert path.stat().st_size > 0


def test_policies_are_sync_only_and_the_scenario_must_exist():
    with pytest.raises(ValueError, match="sync scenario only"):
        run_scenario("handover", {"near": HandoverSettings(goal="near", trials=1)}, policies=["passive"])
    with pytest.raises(ValueError, match="scenario must be one of"):
        run_scenario("dance", {"near": SyncSettings(goal="near", trials=1)})
