"""What does a smoother goal cost on recorded arm reaches?

The people model's goal is recomputed from scratch at each update, so it moves as fast as the evidence
does: on the development arm reaches its error falls from about 0.4 to 0.2 of the distance between a quarter
and half of the movement time, about a dozen updates at 125 Hz, and a goal that uses each update's evidence
at once moves with it. A causal average of its goals, an
exponential one with time constant tau_s (g_k = g_(k-1) + (1 - exp(-dt / tau_s)) (p_k - g_(k-1)), reset
at the onset), moves less per update and lags the evidence. Each reach is streamed as a live tracker
delivers it (as in benchmarks/real_people.py --source arms) and scored with a people model fitted on the
other half of the split (the reaches of the other parity).

Beside the average, the estimator's own rule (:mod:`comanip.estimation.calibration.goal_smoothing`): the goal's motion up
to a free rate (reach distances per second) passes on at once, and only the excess is averaged, so a goal
drifting as evidence accrues is not delayed while a step is spread out.

``--people``: the same rules on the eleven recorded arm people (TAT-HUM's and UE_ADL's, as
benchmarks/forecast_peers.py reads them), each person's reaches scored with the people model fitted on the other
people only, and a rule chosen for each person from the other people's scores alone (:func:`chosen_rule`): of the
rules that cost at most 0.005 D from half of the movement on (median over the other people), the one whose most
jumping other person jumps least.

Printed as a markdown block (progress on stderr): per rule, error / D (median) at 25/50/75/90 % of the movement
time and the share of updates after a quarter of it that move the goal by more than 0.1 D; with ``--people``
per person too, and the rule chosen for each.

    PYTHONPATH=src python -m studies.what_does_a_smoother_arm_goal_cost.measure_smoothing [--limit N]
    PYTHONPATH=src python -m studies.what_does_a_smoother_arm_goal_cost.measure_smoothing --people [--fits DIR]
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings
from pathlib import Path

import numpy as np

from comanip.estimation.calibration.goal_smoothing import GoalSmoother, GoalSmoothing
from comanip.estimation.people.people_model import PeopleModel

from studies.arm_reaches import streamed_arm_reaches  # noqa: E402

FRACTIONS = (0.25, 0.5, 0.75, 0.9)
TIME_CONSTANTS_S = (0.0, 0.008, 0.016, 0.032, 0.064)
FREE_RATES = ((2.5, 0.016), (3.75, 0.016), (6.25, 0.016), (1.25, 0.032), (2.5, 0.032), (3.75, 0.032), (6.25, 0.032),
              (2.5, 0.064), (3.75, 0.064), (6.25, 0.064))
"""(free rate 1/s, time constant s) of the estimator's rule tried."""
JUMP = 0.1
"""A goal moving by more than this fraction of the reach's distance in one update jumps."""
MOST_JUMPS = 0.01
"""The share of updates after a quarter of the movement the goal may jump in, for every person (the target)."""
COST = 0.005
"""Error / D a chosen rule may add to the unsmoothed goal's, at every fraction from half of the movement on."""
UNSMOOTHED = "average, 0 ms"


def people_goals(recording, people: PeopleModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(times (K,) s, the people model's goals (K, d) m and covariances (K, d, d) m²) from the first update it
    answers on."""
    times, goals, covariances = [], [], []
    for k in range(2, len(recording.t) + 1):
        said = people.predict(recording.t[:k], recording.position[:k], recording.velocity[:k], recording.position[0])
        if said is not None:
            times.append(recording.t[k - 1])
            goals.append(said.goal)
            covariances.append(said.covariance)
    return np.array(times), np.array(goals), np.array(covariances)


def free_rate_smoothed(recording, times, goals, covariances, free_rate: float, time_constant: float) -> np.ndarray:
    """The goals as :class:`~comanip.estimation.calibration.goal_smoothing.GoalSmoother` smooths them."""
    smoother = GoalSmoother(GoalSmoothing(free_rate, time_constant), recording.position[0])
    hands = np.array([recording.position_at(t) for t in times])
    return np.array([smoother.smooth(t, g, c, x)[0] for t, g, c, x in zip(times, goals, covariances, hands)])


def smoothed(times: np.ndarray, goals: np.ndarray, time_constant: float) -> np.ndarray:
    """The exponential average (module docstring) of ``goals`` (K, d) m at ``times`` (K,) s."""
    out = goals.copy()
    for k in range(1, len(goals)):
        gain = 1.0 if time_constant == 0 else 1.0 - math.exp(-(times[k] - times[k - 1]) / time_constant)
        out[k] = out[k - 1] + gain * (goals[k] - out[k - 1])
    return out


def free_rate_name(rate: float, time_constant: float) -> str:
    """The name of the estimator's rule with free rate ``rate`` (1/s) and ``time_constant`` (s)."""
    return f"free up to {rate:g} D/s, the excess averaged over {1000 * time_constant:g} ms"


def rules() -> dict:
    """{name: rule(recording, times, goals, covariances) -> smoothed goals} of every rule tried."""
    out = {f"average, {1000 * tau:g} ms": (lambda r, times, goals, covariances, tau=tau: smoothed(times, goals, tau))
           for tau in TIME_CONSTANTS_S}
    out.update({free_rate_name(rate, tau):
                (lambda r, times, goals, covariances, rate=rate, tau=tau: free_rate_smoothed(r, times, goals, covariances, rate, tau))
                for rate, tau in FREE_RATES})
    return out


def scored(recording, trace, rule) -> tuple[dict, np.ndarray]:
    """({fraction: error / D of the smoothed goal seen then}, whether each update after a quarter of the movement
    moved it by more than JUMP D) of one reach's ``trace`` (people_goals) smoothed by ``rule``."""
    times, goals, covariances = trace
    goals = rule(recording, times, goals, covariances)
    errors = {}
    for f in FRACTIONS:
        seen = max(int(np.searchsorted(times, recording.onset + f * recording.movement_time, side="right")) - 1, 0)
        errors[f] = float(np.linalg.norm(goals[seen] - recording.end)) / recording.distance
    late = times[1:] >= recording.onset + 0.25 * recording.movement_time
    return errors, (np.linalg.norm(np.diff(goals, axis=0), axis=1)[late] / recording.distance > JUMP)


def scores(recordings, traces) -> dict:
    """{rule name: (errors (reaches, fractions), jumps: each reach's per-update jumps)}."""
    out = {}
    for name, rule in rules().items():
        each = [scored(recording, trace, rule) for recording, trace in zip(recordings, traces)]
        out[name] = (np.array([[errors[f] for f in FRACTIONS] for errors, _ in each]), [jumps for _, jumps in each])
    return out


def development(argv) -> None:
    recordings = streamed_arm_reaches(__doc__.split("\n\n")[0], argv)
    traces = [None] * len(recordings)
    for parity in (0, 1):
        print(f"half {parity + 1} of 2 ...", file=sys.stderr, flush=True)
        people = PeopleModel.fit(recordings[1 - parity::2], kind="arm")
        for k in range(parity, len(recordings), 2):
            traces[k] = people_goals(recordings[k], people)
    print(f"The people model's goal smoothed over time on the development arm reaches ({len(recordings)}, streamed at "
          f"125 Hz; each reach scored with a model fitted on the other half): error / D, median, and the share of "
          f"updates after 25 % of MT moving the goal by more than {JUMP:g} D\n")
    print("| rule | " + " | ".join(f"{100 * f:g} % of MT" for f in FRACTIONS) + " | updates moving > 0.1 D |")
    print("|---|" + "---|" * (len(FRACTIONS) + 1))
    for name, (errors, jumps) in scores(recordings, traces).items():
        print(f"| {name} | " + " | ".join(f"{v:.3f}" for v in np.median(errors, axis=0))
              + f" | {100 * np.mean(np.concatenate(jumps)):.1f} % |")


def chosen_rule(table: dict, person: str) -> str:
    """The rule for ``person`` from the other people's scores alone: among the rules that cost at most COST D at
    every fraction from half of the movement on (the median over the other people of their median errors, against
    the unsmoothed goal's), the one whose most jumping other person jumps least (ties: the least error at half of
    the movement). ``table``: {rule: {person: (median errors (fractions,), share of jumps)}}."""
    later = [k for k, f in enumerate(FRACTIONS) if f >= 0.5]

    def others(rule):
        return [value for other, value in table[rule].items() if other != person]

    def error(rule):
        return np.median([errors for errors, _ in others(rule)], axis=0)

    free = [rule for rule in table if np.all(error(rule)[later] <= error(UNSMOOTHED)[later] + COST)]
    return min(free, key=lambda rule: (max(jumps for _, jumps in others(rule)), float(error(rule)[later[0]])))


def people_markdown(table: dict, counts: dict) -> str:
    """Per rule the median over people of their median errors and the most jumping person; then person by person
    the rule chosen from the other people (:func:`chosen_rule`) against the unsmoothed goal and the estimator's
    default rule, and the targets."""
    people = list(counts)
    default = GoalSmoothing()
    default_name = free_rate_name(default.free_rate, default.time_constant)
    lines = [f"The people model's goal smoothed over time on {len(people)} arm people ({sum(counts.values())} reaches, "
             "each person's scored with the people model fitted on the other people only): error / D at "
             f"{' / '.join(f'{100 * f:g}' for f in FRACTIONS)} % of MT (the median over people of each person's median) "
             f"and the share of updates after 25 % of MT moving the goal by more than {JUMP:g} D, over people", "",
             "| rule | error / D | jumps: median over people | jumps: most (person) |", "|---|---|---|---|"]
    for rule, by_person in table.items():
        errors = np.median([errors for errors, _ in by_person.values()], axis=0)
        most = max(by_person, key=lambda person: by_person[person][1])
        lines.append(f"| {rule} | {' / '.join(f'{e:.3f}' for e in errors)} | "
                     f"{100 * np.median([jumps for _, jumps in by_person.values()]):.1f} % | "
                     f"{100 * by_person[most][1]:.1f} % ({most}) |")
    lines += ["", f"Person by person: the rule chosen from the other people's scores (of the rules costing at most "
                  f"{COST:g} D from 50 % of MT on, the one whose most jumping other person jumps least), its error / D "
                  "and jumps on the person, beside the unsmoothed goal's and the estimator's default rule's", "",
              "| person | reaches | chosen rule | chosen: error / D; jumps | unsmoothed | default rule |", "|---|---|---|---|---|---|"]
    chosen_jumps, chosen_cost = [], []
    for person in people:
        rule = chosen_rule(table, person)
        cell = lambda name: (f"{' / '.join(f'{e:.3f}' for e in table[name][person][0])}; "
                             f"{100 * table[name][person][1]:.1f} %")
        chosen_jumps.append(table[rule][person][1])
        chosen_cost.append(table[rule][person][0][1] - table[UNSMOOTHED][person][0][1])
        lines.append(f"| {person} | {counts[person]} | {rule} | {cell(rule)} | {cell(UNSMOOTHED)} | {cell(default_name)} |")
    worst = people[int(np.argmax(chosen_jumps))]
    everyone = chosen_rule(table, None)
    lines += ["", f"Chosen the same way on all {len(people)} people: {everyone} "
                  f"(jumps at most {100 * max(jumps for _, jumps in table[everyone].values()):.1f} %; the estimator's "
                  f"default: {default_name}, at most {100 * max(jumps for _, jumps in table[default_name].values()):.1f} %)."]
    lines += ["", "| target (leave-one-person-out) | measured | met |", "|---|---|---|",
              f"| after 25 % of MT, ≤ {100 * MOST_JUMPS:g} % of updates move the goal by > {JUMP:g} D (every person, the rule "
              f"chosen without them) | at most {100 * max(chosen_jumps):.1f} % ({worst}) | "
              f"{'yes' if max(chosen_jumps) <= MOST_JUMPS else 'no'} |",
              f"| what the chosen rule costs at 50 % of MT (its error − the unsmoothed goal's, / D) | median "
              f"{np.median(chosen_cost):+.3f}, at most {max(chosen_cost):+.3f} | – |"]
    return "\n".join(lines)


def over_people(argv) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from forecast_peers import add_people_arguments, people_models, people_of  # noqa: E402  (the benchmarks' folds)

    parser = add_people_arguments(argparse.ArgumentParser(description=__doc__.split("\n\n")[0]))
    parser.add_argument("--people", action="store_true", required=True)
    parser.add_argument("--fits", type=Path, default=None, help="a folder to keep the people models in for the next run")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    people = people_of(args, parser)
    models = people_models(people, args.fits, sys.stderr)
    table: dict = {}
    for i, (person, recordings) in enumerate(people.items()):
        print(f"  {i + 1}/{len(people)} {person}: {len(recordings)} reaches ...", file=sys.stderr, flush=True)
        traces = [people_goals(recording, models[person]) for recording in recordings]
        for rule, (errors, jumps) in scores(recordings, traces).items():
            table.setdefault(rule, {})[person] = (np.median(errors, axis=0), float(np.mean(np.concatenate(jumps))))
    print(people_markdown(table, {person: len(recordings) for person, recordings in people.items()}))


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else list(argv)
    (over_people if "--people" in argv else development)(argv)


if __name__ == "__main__":
    main()
