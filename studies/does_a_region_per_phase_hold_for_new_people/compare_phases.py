"""Does the people model's 95 % region hold as often late in a reach as early, for people it was not fitted on?

The people model (:mod:`comanip.estimation.people.people_model`) scales its predicted squared error by a coverage
factor that makes the 95 % region hold 95 % of the fitting samples' endpoints, out of sample. One factor over every
sample holds on average over the movement, not at each phase of it. With P phases (bins of the predicted share of
the path still to go, each holding as many fitting samples) each phase gets its own factor. On the eleven recorded
arm people (TAT-HUM's and UE_ADL's, as benchmarks/forecast_peers.py reads them), each person's reaches are scored
with the arm people model fitted on the other ten people only, for each P of :data:`PHASES`: whether the region
holds the recorded endpoint at 10 / 25 / 50 / 75 / 90 % of the movement time (a new person's reach: nothing
learned across their reaches).

Chosen (:func:`chosen_phases`): the P whose coverage lies nearest 95 % over people and fractions from 25 % on (the
mean of |coverage - 95 %|, each person's coverage at each fraction).

Printed as a markdown block (progress on stderr).

    PYTHONPATH=src python -m studies.does_a_region_per_phase_hold_for_new_people.compare_phases
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

from comanip.estimation.people.people_model import PHASE_BINS, PeopleModel

FRACTIONS = (0.1, 0.25, 0.5, 0.75, 0.9)
SCORED_FROM = 0.25
"""The choice reads the fractions from this one on (a region at the onset is the stopping distance's)."""
PHASES = (1, 3, 5, 10)
"""The counts of phases compared."""
BAND = (0.80, 0.98)
"""The band a new person's coverage should lie in, at each fraction."""


def coverage(recordings, model: PeopleModel, holds) -> np.ndarray:
    """Whether the 95 % region holds the recorded endpoint, by ``holds(error, covariance)``: (reaches, fractions)
    booleans."""
    out = np.zeros((len(recordings), len(FRACTIONS)), dtype=bool)
    for i, r in enumerate(recordings):
        for j, f in enumerate(FRACTIONS):
            k = max(r.seen_until(f), 2)
            said = model.predict(r.t[:k], r.position[:k], r.velocity[:k], r.position[0])
            out[i, j] = said is not None and holds(r.end - said.goal, said.covariance)
    return out


def chosen_phases(table: dict) -> int:
    """The P (a key of ``table``: {P: {person: coverage (fractions,)}}) nearest 95 % (module docstring)."""
    scored = [j for j, f in enumerate(FRACTIONS) if f >= SCORED_FROM]
    return min(table, key=lambda P: np.mean([np.abs(c[scored] - 0.95) for c in table[P].values()]))


def markdown(table: dict, counts: dict) -> str:
    people = list(counts)
    scored = [j for j, f in enumerate(FRACTIONS) if f >= SCORED_FROM]
    fractions = " / ".join(f"{100 * f:g}" for f in FRACTIONS)
    lines = [f"The arm people model's 95 % region on {len(people)} arm people ({sum(counts.values())} reaches, each "
             "person's scored with the model fitted on the other people only), with a coverage factor for each of P "
             f"phases of the movement: how often it holds the recorded endpoint at {fractions} % of MT", "",
             f"| phases P | all reaches | people within {100 * BAND[0]:g}–{100 * BAND[1]:g} % at every fraction from "
             f"{100 * SCORED_FROM:g} % | person-fractions within the band | mean distance from 95 % |", "|---|---|---|---|---|"]
    for P, by_person in table.items():
        pooled = np.sum([by_person[p] * counts[p] for p in people], axis=0) / sum(counts.values())
        inside = {p: (by_person[p][scored] >= BAND[0]) & (by_person[p][scored] <= BAND[1]) for p in people}
        distance = np.mean([np.abs(by_person[p][scored] - 0.95) for p in people])
        lines.append(f"| {P} | " + " / ".join(f"{100 * c:.0f}" for c in pooled) + " % | "
                     f"{sum(bool(v.all()) for v in inside.values())} of {len(people)} | "
                     f"{sum(int(v.sum()) for v in inside.values())} of {len(people) * len(scored)} | {100 * distance:.1f} % |")
    lines += ["", f"Person by person: coverage at {fractions} % of MT", "",
              "| person | reaches | " + " | ".join(f"P = {P}" for P in table) + " |", "|---|---|" + "---|" * len(table)]
    for p in people:
        lines.append(f"| {p} | {counts[p]} | " + " | ".join(" / ".join(f"{100 * c:.0f}" for c in table[P][p]) + " %"
                                                        for P in table) + " |")
    chosen = chosen_phases(table)
    lines += ["", f"Chosen (the P nearest 95 % over people and fractions from {100 * SCORED_FROM:g} %): {chosen}. "
              f"The arm people model is fitted with {PHASE_BINS['arm']}. With {min(counts.values())}–{max(counts.values())} "
              f"reaches a person, a region that holds 95 % of the time for everyone lies within the band at one fraction "
              f"with probability {band_chance(min(counts.values())):.2f} for the person of fewest reaches."]
    return "\n".join(lines)


def band_chance(reaches: int, rate: float = 0.95) -> float:
    """The probability that a region holding with probability ``rate`` holds in a share within BAND of ``reaches``."""
    from scipy.stats import binom
    low, high = int(np.ceil(BAND[0] * reaches - 1e-9)), int(np.floor(BAND[1] * reaches + 1e-9))
    return float(binom.cdf(high, reaches, rate) - binom.cdf(low - 1, reaches, rate))


def main(argv=None) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from forecast_peers import leave_one_person_out, people_from_command_line  # noqa: E402  (the benchmarks' folds)
    from forecast_scores import holds  # noqa: E402  (the benchmarks' check of a region)

    warnings.simplefilter("ignore")
    people = people_from_command_line(__doc__.split("\n\n")[0], argv)
    table: dict = {}
    for P in PHASES:
        print(f"P = {P} ...", file=sys.stderr, flush=True)
        for person, model in leave_one_person_out(people, lambda recordings: PeopleModel.fit(recordings, kind="arm", phases=P)):
            table.setdefault(P, {})[person] = coverage(people[person], model, holds).mean(axis=0)
            print(f"  {person}: {np.round(100 * table[P][person])}", file=sys.stderr, flush=True)
    print(markdown(table, {person: len(recordings) for person, recordings in people.items()}))


if __name__ == "__main__":
    main()
