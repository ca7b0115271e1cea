"""Explanations of a reach in progress, each giving a goal, its covariance and whether it explains the hand: a hand
still at its start, the reaching model at its own pace, at the person's pace, and the model of recorded people."""

from comanip.estimation.explanations.at_rest import HandAtRest
from comanip.estimation.explanations.base import Explained, Explanation, HandTrace, Reach
from comanip.estimation.explanations.own_pace import ModelAtOwnPace
from comanip.estimation.explanations.people import RecordedPeople
from comanip.estimation.explanations.person_pace import ModelAtPersonPace

__all__ = ["Explained", "Explanation", "HandAtRest", "HandTrace", "ModelAtOwnPace", "ModelAtPersonPace", "Reach", "RecordedPeople"]
