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

Printed as a markdown block (progress on stderr): per rule, error / D (median) at 25/50/75/90 % of the movement
time and the share of updates after a quarter of it that move the goal by more than 0.1 D.

    PYTHONPATH=src python -m studies.what_does_a_smoother_arm_goal_cost.measure_smoothing [--limit N]
"""

from __future__ import annotations

import math
import sys

import numpy as np

from comanip.estimation.calibration.goal_smoothing import GoalSmoother, GoalSmoothing
from comanip.estimation.people.people_model import PeopleModel

from studies.arm_reaches import streamed_arm_reaches  # noqa: E402

FRACTIONS = (0.25, 0.5, 0.75, 0.9)
TIME_CONSTANTS_S = (0.0, 0.008, 0.016, 0.032, 0.064)
FREE_RATES = ((2.5, 0.016), (3.75, 0.016), (6.25, 0.016), (3.75, 0.032), (6.25, 0.032))
"""(free rate 1/s, time constant s) of the estimator's rule tried."""
JUMP = 0.1
"""A goal moving by more than this fraction of the reach's distance in one update jumps."""


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


def main(argv=None) -> None:
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
    rules = {f"average, {1000 * tau:g} ms": (lambda r, times, goals, covariances, tau=tau: smoothed(times, goals, tau))
             for tau in TIME_CONSTANTS_S}
    rules.update({f"free up to {rate:g} D/s, the excess averaged over {1000 * tau:g} ms":
                  (lambda r, times, goals, covariances, rate=rate, tau=tau: free_rate_smoothed(r, times, goals, covariances, rate, tau))
                  for rate, tau in FREE_RATES})
    for name, rule in rules.items():
        errors, jumps = {f: [] for f in FRACTIONS}, []
        for recording, (times, goals, covariances) in zip(recordings, traces):
            goals = rule(recording, times, goals, covariances)
            for f in FRACTIONS:
                seen = max(int(np.searchsorted(times, recording.onset + f * recording.movement_time, side="right")) - 1, 0)
                errors[f].append(float(np.linalg.norm(goals[seen] - recording.end)) / recording.distance)
            late = times[1:] >= recording.onset + 0.25 * recording.movement_time
            moved = np.linalg.norm(np.diff(goals, axis=0), axis=1)[late] / recording.distance
            jumps += list(moved > JUMP)
        print(f"| {name} | " + " | ".join(f"{np.median(v):.3f}" for v in errors.values())
              + f" | {100 * np.mean(jumps):.1f} % |")


if __name__ == "__main__":
    main()
