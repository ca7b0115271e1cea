"""Explanations of a reach in progress, each giving a goal, its covariance and its verdict on the hand: a hand
still at its start, the reaching model at its own pace, at the person's pace, and the model of recorded people;
vetoes that rule an explanation out for the rest of the reach."""

from comanip.estimation.online.explanations.at_rest import HandAtRest
from comanip.estimation.online.explanations.base import Explained, Explanation, HandTrace, Reach, Verdict
from comanip.estimation.online.explanations.default_chain import default_explanations, vetoed_own_pace
from comanip.estimation.online.explanations.own_pace import ModelAtOwnPace
from comanip.estimation.online.explanations.people import RecordedPeople
from comanip.estimation.online.explanations.person_pace import ModelAtPersonPace, PaceContradiction
from comanip.estimation.online.explanations.vetoed import MisfitAbove, Veto, Vetoed

__all__ = ["Explained", "Explanation", "HandAtRest", "HandTrace", "MisfitAbove", "ModelAtOwnPace", "ModelAtPersonPace",
           "PaceContradiction", "Reach", "RecordedPeople", "Verdict", "Veto", "Vetoed",
           "default_explanations", "vetoed_own_pace"]
