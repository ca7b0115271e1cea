"""The online estimator composed of explanations: the first that explains the hand gives the estimate, a
user's own explanation plugs in, and the model-timing estimator is the own-pace explanation alone."""

from pathlib import Path

import numpy as np
import pytest

from comanip.estimation import OnlineGoalEstimator, OnlineOptions
from comanip.estimation.online.explanations import (Explained, HandAtRest, HandTrace, MisfitAbove, ModelAtOwnPace, ModelAtPersonPace,
                                             PaceContradiction, RecordedPeople, Verdict, Vetoed)
from comanip.estimation.estimate_status import EstimateStatus
from comanip.optim import Status


class FixedGoal:
    """An explanation that explains the hand, or not, with one goal."""

    def __init__(self, goal, explains):
        self.goal, self.explains, self.asked = np.asarray(goal, dtype=float), explains, 0

    def reset(self, reach):
        self.reach = reach

    def explain(self, hand, latest):
        self.asked += 1
        if self.explains:
            return Explained.explaining(self.goal, 1e-4 * np.eye(3), Status.SOLVED, f"fixed at {self.goal.tolist()}")
        return Explained(self.goal, 1e-4 * np.eye(3), Verdict.MISFITS, f"fixed at {self.goal.tolist()}")


def reach_samples(planner, goal):
    plan = planner.solve(np.zeros(6), goal)
    return plan.t[1:40], plan.ee_mean[1:40], plan.ee_velocity[1:40]


@pytest.fixture(scope="module")
def planner(cartesian_planner):
    OnlineGoalEstimator(cartesian_planner, np.zeros(6))       # builds the reach family once
    return cartesian_planner


def test_the_default_explanations_in_order(planner):
    chain = OnlineGoalEstimator(planner, np.zeros(6)).explanations
    assert [type(e) for e in chain] == [HandAtRest, Vetoed, RecordedPeople]
    assert type(chain[1].explanation) is ModelAtOwnPace and [type(v) for v in chain[1].vetoes] == [MisfitAbove]
    chain = OnlineGoalEstimator(planner, np.zeros(6), options=OnlineOptions(timing="paced")).explanations
    assert [type(e) for e in chain] == [HandAtRest, Vetoed, ModelAtPersonPace, RecordedPeople]
    assert type(chain[1].explanation) is ModelAtOwnPace
    assert [type(v) for v in chain[1].vetoes] == [PaceContradiction, MisfitAbove] and chain[1].vetoes[0].paced is chain[2]
    assert [type(e) for e in OnlineGoalEstimator(planner, np.zeros(6), options=OnlineOptions(timing="model")).explanations] == [ModelAtOwnPace]


def test_the_first_explanation_that_explains_gives_the_estimate(planner):
    t, position, velocity = reach_samples(planner, np.array([0.3, 0.1, 0.0]))
    skipped, taken, never = FixedGoal([9.0, 0, 0], False), FixedGoal([0.2, 0.2, 0.2], True), FixedGoal([5.0, 0, 0], True)
    estimator = OnlineGoalEstimator(planner, np.zeros(6), explanations=[skipped, taken, never])
    for k in range(len(t)):
        estimate = estimator.update(t[k], position[k], velocity[k])
    np.testing.assert_array_equal(estimate.goal, taken.goal)
    assert never.asked == 0 and skipped.asked == taken.asked == len(t)
    assert estimate.message == "fixed at [9.0, 0.0, 0.0]; fixed at [0.2, 0.2, 0.2]"


def test_no_explanation_leaves_the_prior(planner):
    estimator = OnlineGoalEstimator(planner, np.zeros(6), prior_goal=[0.1, 0.2, 0.3], explanations=[FixedGoal([1.0, 0, 0], False)])
    estimate = estimator.update(0.05, np.array([0.01, 0.0, 0.0]), np.array([0.3, 0.0, 0.0]))
    assert estimate.status == EstimateStatus.UNINFORMATIVE
    np.testing.assert_array_equal(estimate.goal, [0.1, 0.2, 0.3])


def test_model_timing_is_the_own_pace_explanation_alone(planner):
    t, position, velocity = reach_samples(planner, np.array([0.25, -0.1, 0.05]))
    options = OnlineOptions(timing="model")
    by_timing = OnlineGoalEstimator(planner, np.zeros(6), options=options)
    composed = OnlineGoalEstimator(planner, np.zeros(6), explanations=[ModelAtOwnPace(planner.model, options)])
    for k in range(len(t)):
        a, b = by_timing.update(t[k], position[k], velocity[k]), composed.update(t[k], position[k], velocity[k])
        np.testing.assert_array_equal(a.goal, b.goal)
        np.testing.assert_array_equal(a.goal_covariance, b.goal_covariance)
    assert np.linalg.norm(a.goal - [0.25, -0.1, 0.05]) < 1e-3


def test_the_hand_trace_grows_past_its_first_block():
    trace = HandTrace(2)
    for k in range(200):
        trace.append(0.01 * k, np.array([k, -k], dtype=float), np.array([1.0, 2.0]))
    assert trace.count == 200 and trace.last_time == pytest.approx(1.99)
    np.testing.assert_array_equal(trace.position[:, 0], np.arange(200))
    np.testing.assert_array_equal(trace.last_observation, [199, -199, 1, 2])



class ScriptedMisfit:
    """An explanation that always explains the hand, with the misfit its script gives at each update."""

    def __init__(self, misfits, contestable=True):
        self.misfits, self.contestable, self.asked = list(misfits), contestable, 0

    def reset(self, reach):
        self.asked = 0

    def explain(self, hand, latest):
        misfit = self.misfits[min(self.asked, len(self.misfits) - 1)]
        self.asked += 1
        return Explained.explaining(np.array([0.3, 0.0, 0.0]), 1e-4 * np.eye(3), Status.SOLVED, "scripted",
                                    misfit=misfit, contestable=self.contestable)


def moving_hand(count):
    hand = HandTrace(3)
    for k in range(count):
        hand.append(0.01 * k, np.array([0.01 * k, 0.0, 0.0]), np.array([1.0, 0.0, 0.0]))
    return hand


def test_a_veto_rules_an_explanation_out_for_the_rest_of_the_reach(planner):
    reach = OnlineGoalEstimator(planner, np.zeros(6)).reach
    stage = Vetoed(ScriptedMisfit([1.0, 1.0, 20.0, 1.0, 1.0]), (MisfitAbove(9.0, "the script"),))
    stage.reset(reach)
    verdicts = [stage.explain(moving_hand(k + 5), None).verdict for k in range(5)]
    assert verdicts == [Verdict.EXPLAINS, Verdict.EXPLAINS, Verdict.RULED_OUT, Verdict.RULED_OUT, Verdict.RULED_OUT]
    assert stage.explanation.asked == 3 and "misfit 20 per observed number" in stage.ruled_out
    stage.reset(reach)                                   # a new reach: in again
    assert stage.explain(moving_hand(5), None).explains


def test_an_account_that_cannot_be_contested_or_a_hand_at_rest_is_not_vetoed(planner):
    reach = OnlineGoalEstimator(planner, np.zeros(6)).reach
    uncontested = Vetoed(ScriptedMisfit([50.0], contestable=False), (MisfitAbove(9.0, "the script"),))
    uncontested.reset(reach)
    assert uncontested.explain(moving_hand(8), None).explains
    resting = HandTrace(3)
    for k in range(8):
        resting.append(0.01 * k, np.zeros(3), np.zeros(3))
    before_onset = Vetoed(ScriptedMisfit([50.0]), (MisfitAbove(9.0, "the script"),))
    before_onset.reset(reach)
    assert before_onset.explain(resting, None).explains and before_onset.ruled_out is None


def test_an_account_gives_a_status_exactly_when_it_explains_the_hand():
    with pytest.raises(ValueError, match="status"):
        Explained(np.zeros(3), np.eye(3), Verdict.MISFITS, "no", Status.SOLVED)
    with pytest.raises(ValueError, match="status"):
        Explained(np.zeros(3), np.eye(3), Verdict.EXPLAINS, "yes")


EXAMPLE_ARMS = Path(__file__).resolve().parents[3] / "examples" / "data" / "arm_reaches" / "tathum" / "data_3d"


def test_leaving_out_the_person_pace_changes_no_estimate_it_would_not_have_given():
    """On recorded arm reaches (the examples' copy) the model at the person's pace neither explains the hand nor vetoes
    the model at its own pace in any update, so the default chain, which does not ask it, gives every estimate the
    chain with it (timing="paced") gives, to the bit; a reach at another pace of the model's own, where it does
    explain, tells them apart."""
    import comanip
    from comanip.recordings import load_tathum
    model = comanip.presets.load("arm")
    reaches = [trial.streamed_recording() for trial in load_tathum(EXAMPLE_ARMS)[:4]]
    assert reaches
    for reach in reaches:
        chains = {timing: OnlineGoalEstimator(model, np.r_[reach.position[0], np.zeros(model.state_size - model.n)],
                                              options=OnlineOptions(timing=timing)) for timing in ("estimated", "paced")}
        for k in range(len(reach.t)):
            default, paced = (chains[timing].update(reach.t[k], reach.position[k], reach.velocity[k]) for timing in chains)
            assert "person's pace" not in paced.message.split("; ")[-1]
            np.testing.assert_array_equal(default.goal, paced.goal)
            np.testing.assert_array_equal(default.goal_covariance, paced.goal_covariance)
            np.testing.assert_array_equal(default.forecast.mean, paced.forecast.mean)
        assert chains["paced"].explanations[1].ruled_out == chains["estimated"].explanations[1].ruled_out
    planar = comanip.presets.planar()
    plan = comanip.Planner(planar).solve(np.zeros(4), [0.3, 0.1], 0.02)
    t = np.arange(0.0, plan.t[-1] * 1.4, 0.01)
    position = np.column_stack([np.interp(t, plan.t * 1.4, plan.ee_mean[:, i]) for i in range(2)])
    velocity = np.column_stack([np.interp(t, plan.t * 1.4, plan.ee_velocity[:, i]) for i in range(2)]) / 1.4
    chains = [OnlineGoalEstimator(planar, np.zeros(4), options=OnlineOptions(timing=timing)) for timing in ("estimated", "paced")]
    differ = [not np.array_equal(*(chain.update(t[k], position[k], velocity[k]).goal for chain in chains)) for k in range(len(t))]
    assert any(differ)


def test_the_model_at_its_own_pace_gives_up_only_where_its_solve_would_be_vetoed(planner):
    """The model's reach played in 0.3 of its time: at the goal its solve starts from, the misfit exceeds the give-up level,
    so it misfits without iterating and the veto rules it out, as it rules out the solved account on the same
    observations; on the model's own reach it never gives up."""
    from comanip.estimation.online.explanations.own_pace import GIVE_UP_FACTOR
    plan = planner.solve(np.zeros(6), [0.3, 0.1, 0.0])
    options = OnlineOptions()
    level = GIVE_UP_FACTOR * options.mismatch_threshold
    for pace, gives_up in ((0.3, True), (1.0, False)):
        t = np.arange(0.01, plan.t[-1] * pace, 0.01)
        position = np.column_stack([np.interp(t, plan.t * pace, plan.ee_mean[:, i]) for i in range(3)])
        velocity = np.column_stack([np.interp(t, plan.t * pace, plan.ee_velocity[:, i]) for i in range(3)]) / pace
        quick, solved = (OnlineGoalEstimator(planner, np.zeros(6), explanations=[
            Vetoed(ModelAtOwnPace(planner.model, options, give_up_above=above), [MisfitAbove(options.mismatch_threshold, "own")])])
            for above in (level, None))
        answers = []
        for k in range(len(t)):
            quick.update(t[k], position[k], velocity[k])
            solved.update(t[k], position[k], velocity[k])
            answers.append(quick.explanations[0].explanation._last)
        assert (quick.explanations[0].ruled_out is not None) == (solved.explanations[0].ruled_out is not None) == gives_up
        gave_up = [a for a in answers if a is not None and a.verdict is Verdict.MISFITS]
        assert bool(gave_up) == gives_up and all(a.misfit > level and a.iterations == 0 for a in gave_up)


def test_the_model_at_its_own_pace_misfits_a_hand_beyond_its_best_reach():
    """Recorded arm reaches (the examples' copy), streamed from before their onset: where the model at its own pace is
    first asked, its best reach from t = 0 is the family's shortest while the hand has gone farther, so it says it
    misfits without solving and is ruled out; solved instead, its goal stays at that shortest distance, behind the
    hand."""
    import comanip
    from comanip.recordings import load_tathum
    model = comanip.presets.load("arm")
    for reach in [trial.streamed_recording() for trial in load_tathum(EXAMPLE_ARMS)[:3]]:
        start = np.r_[reach.position[0], np.zeros(model.state_size - model.n)]
        options = OnlineOptions()
        quick = OnlineGoalEstimator(model, start)
        solved = OnlineGoalEstimator(model, start, explanations=[HandAtRest(), ModelAtOwnPace(model, options)])
        for k in range(len(reach.t)):
            quick.update(reach.t[k], reach.position[k], reach.velocity[k])
            answer = solved.update(reach.t[k], reach.position[k], reach.velocity[k])
            first = quick.explanations[1].explanation._last
            if first is not None:
                break
        shortest = quick.family.distances[0]
        assert first.verdict is Verdict.MISFITS and first.misfit == np.inf and quick.explanations[1].ruled_out is not None
        assert np.linalg.norm(answer.unsmoothed_goal - reach.position[0]) <= 1.01 * shortest
        assert np.linalg.norm(reach.position[k] - reach.position[0]) > shortest


def test_the_model_at_its_own_pace_cannot_tell_before_movement_and_the_next_explanation_answers(planner):
    """Before any observation shows movement the model at its own pace is undecided (not the prior as its account):
    the next explanation gives the estimate; once the hand moves, the model explains it and the next is not asked."""
    t, position, velocity = reach_samples(planner, np.array([0.3, 0.1, 0.0]))
    after = FixedGoal([0.2, 0.2, 0.2], True)
    estimator = OnlineGoalEstimator(planner, np.zeros(6), explanations=[ModelAtOwnPace(planner.model, OnlineOptions()), after])
    resting = estimator.update(0.01, np.zeros(3), np.zeros(3))
    assert after.asked == 1 and resting.status == Status.SOLVED
    np.testing.assert_array_equal(resting.goal, after.goal)
    for k in range(len(t)):
        moving = estimator.update(0.01 + t[k], position[k], velocity[k])
    assert after.asked < 1 + len(t)                                   # the model explained the moving hand
    assert np.linalg.norm(moving.goal - [0.3, 0.1, 0.0]) < 0.05       # its goal, not the fixed one 0.2 m away
