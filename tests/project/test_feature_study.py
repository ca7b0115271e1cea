"""The feature study's choice (studies/which_movement_features_carry_across_people): of the sets within its cost of
the lowest error at every fraction, the one whose most jumping person jumps least."""

import numpy as np

from studies.which_movement_features_carry_across_people import compare_features as study


def scores(error: float, jumps: dict) -> dict:
    return {person: {"error": np.full(len(study.FRACTIONS), error), "jumps": share, "smoothed jumps": share / 2}
            for person, share in jumps.items()}


def test_the_set_chosen_is_the_calmest_of_those_near_the_lowest_error():
    table = {"accurate": scores(0.200, {"P": 0.10, "Q": 0.02}),
             "calm and near": scores(0.200 + 0.8 * study.COST, {"P": 0.04, "Q": 0.03}),
             "calmest but far": scores(0.200 + 2 * study.COST, {"P": 0.00, "Q": 0.00})}
    assert study.chosen_set(table) == "calm and near"
    # one person jumping more with it is enough to lose the choice
    table["calm and near"]["Q"]["jumps"] = 0.2
    assert study.chosen_set(table) == "accurate"
    # a set as near at three fractions but far at one is not near
    table["calm and near"] = {person: {**s, "jumps": 0.0} for person, s in table["calm and near"].items()}
    table["calm and near"]["P"]["error"] = table["calm and near"]["Q"]["error"] = np.array([0.2, 0.2, 0.2, 0.3])
    assert study.chosen_set(table) == "accurate"
