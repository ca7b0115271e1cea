"""Should every sample, every reach or every person weigh alike when an arm people model is fitted?

The people model (:mod:`comanip.estimation.people.people_model`) is fitted on every sample of its recordings from
the onset to the end. Recorded arm people differ in their trackers and paces: TAT-HUM's person reaches for about
0.45 s under a tracker streamed at 125 Hz, UE_ADL's people for about a second at 100 Hz, so one of UE_ADL's reaches
brings about twice the samples of one of TAT-HUM's, and TAT-HUM's person brings 173 reaches where each of UE_ADL's
brings 20. On the eleven recorded arm people (as benchmarks/forecast_peers.py reads them), each person's reaches are
scored with the people model fitted on the other ten people only, for each weighting (:data:`WEIGHTINGS`): the
unsmoothed goal's error / D at 25 / 50 / 75 / 90 % of the movement time and the share of updates after a quarter of
it that move the goal by more than 0.1 D, unsmoothed and with the estimator's goal smoothing (as
``studies/which_movement_features_carry_across_people`` scores its sets of features).

The weighting chosen is made by that study's rule (``compare_features.chosen_set``): of the weightings whose error (median over
people) is within ``COST`` D of the lowest at every fraction, the one whose most jumping person jumps least,
unsmoothed.

Printed as a markdown block (progress on stderr).

    PYTHONPATH=src python -m studies.should_every_reach_weigh_alike.compare_weightings
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from comanip.estimation.people.people_model import WEIGHTING, PeopleModel

from studies.which_movement_features_carry_across_people.compare_features import markdown, scored_people

WEIGHTINGS = {
    "every sample alike": "sample",
    "every reach alike": "reach",
    "every person alike": "person",
}
"""The weightings compared, by name: ``PeopleModel.fit``'s ``weights`` ("sample", "reach"), or "person": each
recording weighs one over its person's count of recordings."""


def fit_weights(weighting: str, owners: list[str]):
    """``PeopleModel.fit``'s ``weights`` for ``weighting`` (a value of :data:`WEIGHTINGS`), the recordings' people
    ``owners``."""
    if weighting != "person":
        return weighting
    count = {person: owners.count(person) for person in set(owners)}
    return np.array([1.0 / count[person] for person in owners])


def main(argv=None) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from forecast_peers import leave_one_person_out, people_from_command_line  # noqa: E402  (the benchmarks' folds)

    warnings.simplefilter("ignore")
    people = people_from_command_line(__doc__.split("\n\n")[0], argv)
    owner = {r.name: person for person, recordings in people.items() for r in recordings}
    table = {name: scored_people(people, leave_one_person_out(people, lambda recordings: PeopleModel.fit(
        recordings, kind="arm", weights=fit_weights(weighting, [owner[r.name] for r in recordings]))), name)
        for name, weighting in WEIGHTINGS.items()}
    shipped = next(name for name, weighting in WEIGHTINGS.items() if weighting == WEIGHTING["arm"])
    print(markdown(table, {person: len(recordings) for person, recordings in people.items()}, "weightings", shipped))


if __name__ == "__main__":
    main()
