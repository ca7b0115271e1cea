"""The model of recorded people's movements (:class:`~comanip.estimation.people.people_model.PeopleModel`): where people
whose hand moved like this one stopped, and when. It explains any hand that has started to move; its goal is
combined with the prior and never lies behind a hand that has moved past it, and the predicted reach runs from the
hand's onset to when the people model says it stops (a model that does not say when: at the model's own pace)."""

from __future__ import annotations

from comanip.estimation.online.explanations.base import Explained, HandTrace, Reach, Verdict
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.people.people_model import PeopleModel
from comanip.estimation.estimate_status import EstimateStatus
from comanip.estimation.model_reaches.reach_timing import ReachTiming


class RecordedPeople:
    """Where recorded people whose hand moved like this one stopped (module docstring)."""

    def __init__(self, people: PeopleModel):
        self.people = people

    def reset(self, reach: Reach) -> None:
        self.reach = reach

    def explain(self, hand: HandTrace, latest: OnlineEstimate | None) -> Explained:
        reach = self.reach
        predicted = self.people.predict(hand.t, hand.position, hand.velocity, reach.start_position)
        if predicted is None:
            return Explained.not_explaining(reach, Verdict.UNDECIDED, "no onset the people model sees")
        onset = hand.onset()
        timing = None if predicted.end_time is None else ReachTiming(onset, max(predicted.end_time, hand.t[-1]) - onset)
        return reach.landed(Explained.explaining(predicted.goal, predicted.covariance, EstimateStatus.PEOPLE_MODEL,
                                                 "the goal is the people model's", timing=timing), hand.position[-1])
