"""Where the simulated person's reach turns from the fast sub-movement to the corrective one, against the
handover's predicted transition T.

    PYTHONPATH=src python -m studies.does_the_predicted_handover_match_the_person.measure_handover_transition [--trials 20] [--transition-data CSV]
        [--passive PKL ...]
    PYTHONPATH=src python -m studies.does_the_predicted_handover_match_the_person.measure_handover_transition --release [--trials 10]

For the near and far goals: the transition distance T the handover predicts (:class:`TransitionModel` on the
shipped planar data, or on --transition-data, e.g. made by ``comanip transition generate --preset
cartesian``), the distance at which the robot released, the peak of the perpendicular spread of the handle
paths in the handover run, and the same peak for the person alone (a passive robot in the sync scenario,
same seeds: the person's own transition; --passive reuses pickles written by
``studies/which_robot_policy_helps_the_person_in_sync/make_policy_comparison.py --save``). Writes studies/does_the_predicted_handover_match_the_person/handover_transition.md.

With --release: the two release triggers (``HandoverSettings.release_trigger``) over the same trials and
seeds, per goal: when and where the robot let go against the predicted transition and, paired by seed,
against the goal-distance trigger; the estimate at the release; the final placement error and the person's
RMS interaction force. Replaces the block between the release markers of studies/does_the_predicted_handover_match_the_person/handover_transition.md.
"""

from __future__ import annotations

import argparse
import pickle
from pathlib import Path

import numpy as np

from comanip.multicomponent.perpendicular_dispersion import perpendicular_dispersion_profile
from comanip.multicomponent.transition_model import TransitionModel
from comanip.simulation import HandoverSettings, ScenarioSetup, SyncSettings, run_handover, run_sync

DOCS = Path(__file__).resolve().parent
GOALS = ("near", "far")


def spread_peak(paths: np.ndarray, goal: np.ndarray) -> tuple[float, float]:
    """(distance of the perpendicular spread's peak from the goal (m), the peak spread (m)) of paths (N, K, 3)."""
    profile = perpendicular_dispersion_profile(paths, goal)
    return profile.transition_distance, profile.peak_dispersion


RELEASE_BEGIN, RELEASE_END = "<!-- release:begin -->", "<!-- release:end -->"
#: The heading of studies/does_the_predicted_handover_match_the_person/handover_transition.md's section on the release triggers, kept by the default mode.
RELEASE_SECTION = "## What releases the robot"


def _median_iqr(values, scale: float = 1.0, digits: int = 3) -> str:
    """'median [q25, q75]' of the finite values times scale."""
    v = scale * np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return "–"
    q25, q50, q75 = np.percentile(v, [25, 50, 75])
    return f"{q50:.{digits}f} [{q25:.{digits}f}, {q75:.{digits}f}]"


def release_table(trials: int, seed: int) -> str:
    """The markdown block comparing the release triggers (module docstring)."""
    setup = ScenarioSetup(HandoverSettings())
    headings = ["goal", "trigger", "released (ms after predicted t_h)", "released − goal-distance trigger (ms, same seed)",
                "released at (m from goal; predicted T)", "estimate: goal error (mm); T_hat (m)", "fallback",
                "final error (mm)", "RMS force (N); its change (N)"]
    rows = []
    for goal in GOALS:
        runs = {trigger: run_handover(HandoverSettings(goal=goal, trials=trials, seed=seed, release_trigger=trigger), setup,
                                      progress=False) for trigger in ("goal_distance", "estimate")}
        reference = np.array([t.metrics["switch_time_s"] for t in runs["goal_distance"].trials])
        for trigger, run in runs.items():
            m = {key: np.array([t.metrics[key] for t in run.trials], dtype=float)
                 for key in ("switch_time_s", "switch_delay_s", "switch_distance_m", "final_error_m", "rms_force_N",
                             "rms_force_change_N", "estimate_goal_error_m", "estimated_transition_distance_m")}
            fallback = sum(t.metrics["release_fallback"] for t in run.trials)
            estimate = "–" if trigger == "goal_distance" else \
                f"{_median_iqr(m['estimate_goal_error_m'], 1e3, 0)}; {_median_iqr(m['estimated_transition_distance_m'])}"
            rows.append([goal, trigger, _median_iqr(m["switch_delay_s"], 1e3, 0),
                         _median_iqr(m["switch_time_s"] - reference, 1e3, 0),
                         f"{_median_iqr(m['switch_distance_m'])}; {run.schedule.transition_distance:.3f}", estimate,
                         f"{fallback}/{len(run.trials)}", _median_iqr(m["final_error_m"], 1e3, 1),
                         f"{_median_iqr(m['rms_force_N'], 1, 1)}; {_median_iqr(m['rms_force_change_N'], 1, 1)}"])
    table = "\n".join(["| " + " | ".join(headings) + " |", "|" + "---|" * len(headings)] +
                      ["| " + " | ".join(row) + " |" for row in rows])
    command = f"PYTHONPATH=src python -m studies.does_the_predicted_handover_match_the_person.measure_handover_transition --release --trials {trials}"
    return (f"{RELEASE_BEGIN}\nMedian [quartiles] over {trials} trials per goal (seeds {seed}–{seed + trials - 1}, the same "
            f"for both triggers); measured by `{command}`.\n\n{table}\n{RELEASE_END}")


def write_release_block(block: str) -> None:
    """Put block in place of the release markers' block of studies/does_the_predicted_handover_match_the_person/handover_transition.md (or at its end)."""
    path = DOCS / "handover_transition.md"
    text = path.read_text()
    if RELEASE_BEGIN in text:
        text = text[: text.index(RELEASE_BEGIN)] + block + text[text.index(RELEASE_END) + len(RELEASE_END):]
    else:
        text = text.rstrip("\n") + f"\n\n{RELEASE_SECTION}\n\n{block}\n"
    path.write_text(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=20, help="trials per goal (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--transition-data", type=Path, help="transition CSV for the TransitionModel (default: shipped)")
    parser.add_argument("--passive", type=Path, nargs="*", help="pickles of make_policy_comparison.py --save to reuse")
    parser.add_argument("--release", action="store_true", help="compare the release triggers instead (module docstring)")
    args = parser.parse_args(argv)
    if args.release:
        block = release_table(args.trials, args.seed)
        write_release_block(block)
        print(block)
        return 0
    model = TransitionModel() if args.transition_data is None else TransitionModel(data=args.transition_data)
    passive = {}
    for path in args.passive or []:
        for label, by_policy in pickle.loads(path.read_bytes())["results"].items():
            if label in GOALS:
                passive[label] = by_policy["passive"][: args.trials]
    setup = ScenarioSetup(HandoverSettings())
    rows = []
    for goal in GOALS:
        settings = HandoverSettings(goal=goal, trials=args.trials, seed=args.seed)
        run = run_handover(settings, setup, transition_model=model, progress=False)
        alone = passive.get(goal) or run_sync(SyncSettings(goal=goal, trials=args.trials, seed=args.seed, policy="passive"),
                                              ScenarioSetup(SyncSettings(goal=goal)), progress=False)
        target = np.asarray(settings.goal)
        handle_alone = spread_peak(np.stack([t.record.position for t in alone]), target)
        intention_alone = spread_peak(np.stack([t.record.intended_position for t in alone]), target)
        released = [t.metrics["switch_distance_m"] for t in run.trials]
        rows.append([goal, f"{run.schedule.goal_distance:.3f}", f"{run.schedule.transition_distance:.3f}",
                     f"{np.nanmedian(released):.3f}", f"{run.dispersion.transition_distance:.3f}",
                     f"{handle_alone[0]:.3f} ({1e3 * handle_alone[1]:.1f} mm)",
                     f"{intention_alone[0]:.3f} ({1e3 * intention_alone[1]:.1f} mm)"])
    source = "shipped planar data" if args.transition_data is None else f"`{args.transition_data.name}`"
    headings = ["goal", "D (m)", f"predicted T (m, {source})", "released at (m, median)", "handover run: spread peak (m)",
                "person alone: handle spread peak (m, peak spread)", "person alone: intention spread peak (m)"]
    table = "\n".join(["| " + " | ".join(headings) + " |", "|" + "---|" * len(headings)] +
                      ["| " + " | ".join(row) + " |" for row in rows]) + "\n"
    command = f"PYTHONPATH=src python -m studies.does_the_predicted_handover_match_the_person.measure_handover_transition --trials {args.trials}" + \
              (f" --transition-data {args.transition_data}" if args.transition_data else "")
    text = f"Distances from the goal; measured by `{command}` (seeds {args.seed}–{args.seed + args.trials - 1}).\n\n{table}"
    suffix = "" if args.transition_data is None else "_" + args.transition_data.stem
    path = DOCS / f"handover_transition{suffix}.md"
    old = path.read_text() if path.exists() else ""
    if RELEASE_SECTION in old:      # the release triggers' section (its table from --release) stays
        text += "\n" + old[old.index(RELEASE_SECTION):]
    path.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
