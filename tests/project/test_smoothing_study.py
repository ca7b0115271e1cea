"""The smoothing study's rule chosen for a person (studies/what_does_a_smoother_arm_goal_cost, --people) reads only
the other people's scores, keeps within its cost from half of the movement on, and jumps least among those."""

import numpy as np

from studies.what_does_a_smoother_arm_goal_cost import measure_smoothing as study


def table_of(scores: dict) -> dict:
    """{rule: {person: (errors at the study's fractions, share of jumps)}} from {rule: {person: (error, jumps)}},
    one error at every fraction."""
    return {rule: {person: (np.full(len(study.FRACTIONS), error), jumps) for person, (error, jumps) in by_person.items()}
            for rule, by_person in scores.items()}


def test_a_persons_rule_is_chosen_from_the_other_people_alone():
    scores = {study.UNSMOOTHED: {"P": (0.20, 0.10), "Q": (0.20, 0.08), "R": (0.20, 0.09)},
              "calm but costly": {"P": (0.30, 0.00), "Q": (0.30, 0.00), "R": (0.30, 0.00)},
              "calm and cheap": {"P": (0.204, 0.02), "Q": (0.203, 0.01), "R": (0.204, 0.01)},
              "cheapest": {"P": (0.20, 0.05), "Q": (0.20, 0.03), "R": (0.20, 0.04)}}
    table = table_of(scores)
    assert study.chosen_rule(table, "P") == "calm and cheap"         # the costly one is over the cost
    for own in ((0.9, 0.0), (0.0, 0.9)):                               # P's own scores change nothing
        changed = {rule: {**by_person, "P": own} for rule, by_person in scores.items()}
        assert study.chosen_rule(table_of(changed), "P") == "calm and cheap"
    jumpy = {**scores, "calm and cheap": {**scores["calm and cheap"], "Q": (0.203, 0.2)}}
    assert study.chosen_rule(table_of(jumpy), "P") == "cheapest"       # Q now jumps most with it
    assert study.chosen_rule(table_of(jumpy), "Q") == "calm and cheap"  # Q's own jumps are not Q's choice
