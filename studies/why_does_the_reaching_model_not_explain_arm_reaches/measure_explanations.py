"""Why does the reaching model carry none of the online estimates on recorded arm reaches?

Each explanation of the online estimator is run alone on the development arm reaches, streamed as a live
tracker delivers them (as in benchmarks/real_people.py --source arms), with the `arm` preset: its own goal at
25/50/75/90 % of the movement time whatever it says of the hand (error / D, median [IQR]), and the share of the
updates after a quarter of the movement in which it says it explains the hand (as the estimator asks it:
the model at its own pace with its misfit and timing checks, the model at the person's pace with its misfit
and settling checks). Printed as a markdown block (progress on stderr).

    PYTHONPATH=src python -m studies.why_does_the_reaching_model_not_explain_arm_reaches.measure_explanations [--limit N]
"""

from __future__ import annotations

import sys
from dataclasses import replace

import numpy as np

import comanip
from comanip.estimation import OnlineOptions
from comanip.estimation.online.explanations import (HandAtRest, ModelAtOwnPace, ModelAtPersonPace, RecordedPeople, Verdict,
                                             vetoed_own_pace)
from comanip.estimation.model_reaches.paced_model import PacedModel
from comanip.estimation.people.people_model import shipped_people_model
from comanip.optim import Status

from studies.arm_reaches import streamed_arm_reaches  # noqa: E402

FRACTIONS = (0.25, 0.5, 0.75, 0.9)


class Heard:
    """An explanation whose goal is taken whatever it says; what it says after a quarter of the movement is kept."""

    def __init__(self, inner):
        self.inner, self.said = inner, []

    def reset(self, reach):
        self.inner.reset(reach)

    def explain(self, hand, latest):
        explained = self.inner.explain(hand, latest)
        self.said.append((hand.last_time, explained.explains))
        return replace(explained, verdict=Verdict.EXPLAINS, status=explained.status or Status.SOLVED)


def explanations(model, options, family):
    """{name: (factory of the explanation under test, whether its goals are scored)}: the model at its own pace as
    the estimator asks it gives the prior once ruled out, so only what it says of the hand is kept."""
    def person_pace():
        return ModelAtPersonPace(PacedModel(family), options)

    return {
        "the model at its own pace (never ruled out)": (lambda: ModelAtOwnPace(model, options), True),
        "the model at its own pace, as the estimator asks it": (lambda: vetoed_own_pace(model, options, person_pace()), False),
        "the model at the person's pace": (person_pace, True),
        "recorded people (the arm people model)": (lambda: RecordedPeople(shipped_people_model("arm")), True),
    }


def main(argv=None) -> None:
    recordings = streamed_arm_reaches(__doc__.split("\n\n")[0], argv)
    model, options = comanip.presets.arm(), OnlineOptions()
    family = comanip.OnlineGoalEstimator(model, np.zeros(model.state_size)).family
    rows = []
    for name, (make, scored) in explanations(model, options, family).items():
        errors, said = {f: [] for f in FRACTIONS}, []
        for recording in recordings:
            heard = Heard(make())
            estimator = comanip.OnlineGoalEstimator(model, np.r_[recording.position[0], np.zeros(model.state_size - model.n)],
                                                    explanations=[HandAtRest(), heard])
            goals = [estimator.update(t, p, v).goal for t, p, v in zip(recording.t, recording.position, recording.velocity)]
            for f in FRACTIONS:
                k = max(recording.seen_until(f) - 1, 0)
                errors[f].append(float(np.linalg.norm(goals[k] - recording.end)) / recording.distance)
            quarter = recording.onset + 0.25 * recording.movement_time
            said += [explains for t, explains in heard.said if t >= quarter]
        cells = [f"{np.median(e):.3f} [{np.percentile(e, 25):.2f}–{np.percentile(e, 75):.2f}]" if scored else "–"
                 for e in errors.values()]
        rows.append(f"| {name} | " + " | ".join(cells) + f" | {100 * np.mean(said):.0f} % |")
        print(f"  {name}: done", file=sys.stderr, flush=True)
    print(f"Each explanation alone on the development arm reaches ({len(recordings)}, streamed at 125 Hz, `arm` preset): "
          "its goal's error / D, median [IQR], and the share of updates after 25 % of MT in which it says it explains "
          "the hand\n")
    print("| explanation | " + " | ".join(f"{100 * f:g} % of MT" for f in FRACTIONS) + " | explains the hand |")
    print("|---|" + "---|" * (len(FRACTIONS) + 1))
    print("\n".join(rows))


if __name__ == "__main__":
    main()
