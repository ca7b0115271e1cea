"""Which of the movement's numbers should an arm people model read, to carry to people it was not fitted on?

The people model (:mod:`comanip.estimation.people.people_model`) reads numbers without units of the movement so far.
Two of them read the tracker as much as the hand: the straightness |x - x_0| / L (the path length L
integrates the speed, so a noisier tracker makes every path longer) and the acceleration (a difference of two
successive speeds). On the eleven recorded arm people (TAT-HUM's and UE_ADL's, as benchmarks/forecast_peers.py reads
them), each person's reaches are scored with the people model fitted on the other ten people only, for each set of
features (:data:`FEATURE_SETS`): the unsmoothed goal's error / D at 25 / 50 / 75 / 90 % of the movement time and the
share of updates after a quarter of it that move the goal by more than 0.1 D, unsmoothed and with the estimator's
goal smoothing (:class:`~comanip.estimation.calibration.goal_smoothing.GoalSmoothing`'s defaults).

The set chosen (:func:`chosen_set`): of the sets whose error (median over people) is within ``COST`` D of the
lowest at every fraction, the one whose most jumping person jumps least, unsmoothed.

Printed as a markdown block (progress on stderr).

    PYTHONPATH=src python -m studies.which_movement_features_carry_across_people.compare_features
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from comanip.estimation.calibration.goal_smoothing import GoalSmoothing
from comanip.estimation.people.people_model import ARM_FEATURES, SCALE_FREE, PeopleModel

from studies.what_does_a_smoother_arm_goal_cost.measure_smoothing import (FRACTIONS, JUMP, UNSMOOTHED, free_rate_name,
                                                                          people_goals, rules, scored)

FEATURE_SETS = {
    "every feature without units": SCALE_FREE,
    "without the straightness": tuple(f for f in SCALE_FREE if f != "straightness"),
    "without the acceleration": tuple(f for f in SCALE_FREE if f != "acceleration_scaled"),
    "without either": tuple(f for f in SCALE_FREE if f not in ("straightness", "acceleration_scaled")),
}
"""The sets of features compared, by name (each of :data:`~comanip.estimation.people.people_model.SCALE_FREE`)."""
COST = 0.005
"""Error / D a chosen set may have above the lowest, at each fraction of the movement time (median over people)."""


def person_scores(recordings, model: PeopleModel) -> dict:
    """{"error": (fractions,) median error / D, "jumps": share unsmoothed, "smoothed jumps": with the default rule}."""
    traces = [people_goals(recording, model) for recording in recordings]
    default, tried = GoalSmoothing(), rules()
    out = {}
    for name, rule in (("", tried[UNSMOOTHED]), ("smoothed ", tried[free_rate_name(default.free_rate, default.time_constant)])):
        each = [scored(recording, trace, rule) for recording, trace in zip(recordings, traces)]
        if not name:
            out["error"] = np.median([[errors[f] for f in FRACTIONS] for errors, _ in each], axis=0)
        out[name + "jumps"] = float(np.mean(np.concatenate([jumps for _, jumps in each])))
    return out


def chosen_set(table: dict) -> str:
    """The choice (a key of ``table``: {choice: {person: person_scores}}) made as the module docstring says: of the
    choices whose error is within ``COST`` D of the lowest at every fraction, the one whose most jumping person jumps
    least."""
    error = {name: np.median([s["error"] for s in people.values()], axis=0) for name, people in table.items()}
    lowest = np.min(list(error.values()), axis=0)
    near = [name for name in table if np.all(error[name] <= lowest + COST)]
    return min(near, key=lambda name: max(s["jumps"] for s in table[name].values()))


def markdown(table: dict, counts: dict, compared: str = "sets of features", shipped: str | None = None) -> str:
    """The block: ``table`` ({choice: {person: person_scores}}), ``counts`` ({person: reaches}); ``compared``: what the
    choices are (the first column's heading); ``shipped``: the choice an arm people model makes (default: the
    feature set it reads)."""
    people = list(counts)
    if shipped is None:
        shipped = next((name for name, features in FEATURE_SETS.items() if features == ARM_FEATURES), "none of these")
    lines = [f"The people model's goal on {len(people)} arm people ({sum(counts.values())} reaches, each person's scored "
             f"with the people model fitted on the other people only) for each of its {compared}: error / D at "
             f"{' / '.join(f'{100 * f:g}' for f in FRACTIONS)} % of MT (median over people of each person's median) and "
             f"the share of updates after 25 % of MT moving the goal by more than {JUMP:g} D, unsmoothed and with the "
             "estimator's goal smoothing", "",
             f"| {compared} | error / D | jumps: median over people | jumps: most (person) | smoothed jumps: median | smoothed jumps: most (person) |",
             "|---|---|---|---|---|---|"]
    for name, scores in table.items():
        error = np.median([scores[p]["error"] for p in people], axis=0)
        cells = [" / ".join(f"{e:.3f}" for e in error)]
        for key in ("jumps", "smoothed jumps"):
            most = max(people, key=lambda p: scores[p][key])
            cells += [f"{100 * np.median([scores[p][key] for p in people]):.1f} %", f"{100 * scores[most][key]:.1f} % ({most})"]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines += ["", "Person by person: error / D at 50 % of MT; jumps unsmoothed, and with the estimator's smoothing", "",
              "| person | reaches | " + " | ".join(table) + " |", "|---|---|" + "---|" * len(table)]
    for p in people:
        lines.append(f"| {p} | {counts[p]} | " + " | ".join(
            f"{table[name][p]['error'][FRACTIONS.index(0.5)]:.3f}; {100 * table[name][p]['jumps']:.1f} % "
            f"({100 * table[name][p]['smoothed jumps']:.1f} %)" for name in table) + " |")
    lines += ["", f"Chosen (of the {compared} within {COST:g} D of the lowest error at every fraction, the one whose most "
              f"jumping person jumps least): {chosen_set(table)}. An arm people model's: {shipped}."]
    return "\n".join(lines)


def scored_people(people: dict, fits, label: str) -> dict:
    """{person: person_scores} of each (person, model) of ``fits`` on ``people[person]`` ({person: recordings}),
    with progress on stderr under ``label``."""
    print(f"{label} ...", file=sys.stderr, flush=True)
    scores = {}
    for person, model in fits:
        scores[person] = person_scores(people[person], model)
        print(f"  {person}: {np.round(scores[person]['error'], 3)}, jumps {scores[person]['jumps']:.1%}", file=sys.stderr, flush=True)
    return scores


def main(argv=None) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from forecast_peers import leave_one_person_out, people_from_command_line  # noqa: E402  (the benchmarks' folds)

    warnings.simplefilter("ignore")
    people = people_from_command_line(__doc__.split("\n\n")[0], argv)
    table = {name: scored_people(people, leave_one_person_out(
        people, lambda recordings: PeopleModel.fit(recordings, kind="arm", features=features)), f"{name} ({', '.join(features)})")
        for name, features in FEATURE_SETS.items()}
    print(markdown(table, {person: len(recordings) for person, recordings in people.items()}))


if __name__ == "__main__":
    main()
