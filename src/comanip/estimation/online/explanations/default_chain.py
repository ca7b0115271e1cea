"""The explanations an online estimator asks in order unless it is given its own, as ``OnlineOptions.timing`` names
them (:mod:`comanip.estimation.online.online_estimator`):

- ``"model"``: the model at its own pace alone;
- ``"estimated"``: the hand at rest, the model at its own pace (ruled out once its misfit exceeds
  ``OnlineOptions.mismatch_threshold``), the model fitted to recorded people;
- ``"paced"``: the same with the model's reach at the person's pace asked before the people model (and its
  contradiction of the model's timing a veto of the model at its own pace).
"""

from __future__ import annotations

from comanip.estimation.model_reaches.paced_model import PacedModel
from comanip.estimation.model_reaches.reach_family import ReachFamily
from comanip.estimation.online.explanations.at_rest import HandAtRest
from comanip.estimation.online.explanations.base import Explanation
from comanip.estimation.online.explanations.own_pace import GIVE_UP_FACTOR, ModelAtOwnPace
from comanip.estimation.online.explanations.people import RecordedPeople
from comanip.estimation.online.explanations.person_pace import ModelAtPersonPace, PaceContradiction
from comanip.estimation.online.explanations.vetoed import MisfitAbove, Vetoed
from comanip.estimation.online.online_options import OnlineOptions
from comanip.estimation.people.people_model import shipped_people_model
from comanip.model import ReachingModel


def default_explanations(model: ReachingModel, options: OnlineOptions, family: ReachFamily) -> list[Explanation]:
    """The chain ``options.timing`` names (module docstring) for ``model`` and its reach ``family``; a ValueError
    for a people model fitted to mouse movements asked to explain a 3-D reach."""
    if options.timing == "model":
        return [ModelAtOwnPace(model, options)]
    d = model.d
    people = options.people_model or shipped_people_model("arm" if d == 3 else "mouse")
    if d == 3 and people.kind == "mouse":
        raise ValueError("options.people_model was fitted to mouse movements; a 3-D reach is an arm's: fit one "
                         "to arm reaches (PeopleModel.fit(recordings, kind='arm')) or leave it None")
    if options.timing == "estimated":
        return [HandAtRest(), vetoed_own_pace(model, options), RecordedPeople(people)]
    person_pace = ModelAtPersonPace(PacedModel(family), options)
    return [HandAtRest(), vetoed_own_pace(model, options, person_pace), person_pace, RecordedPeople(people)]


def vetoed_own_pace(model: ReachingModel, options: OnlineOptions, person_pace: ModelAtPersonPace | None = None) -> Vetoed:
    """The model at its own pace as the estimator's default chains ask it: ruled out for the rest of the reach
    where its misfit exceeds ``options.mismatch_threshold`` (:class:`MisfitAbove`) or, given ``person_pace``, where
    that contradicts its timing (:class:`PaceContradiction`)."""
    misfit = MisfitAbove(options.mismatch_threshold, "the model at its own pace")
    own_pace = ModelAtOwnPace(model, options, give_up_above=GIVE_UP_FACTOR * options.mismatch_threshold)
    return Vetoed(own_pace, (misfit,) if person_pace is None else (PaceContradiction(person_pace), misfit))
