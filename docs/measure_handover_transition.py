"""Where the simulated person's reach turns from the fast sub-movement to the corrective one, against the
handover's predicted transition T (issue 12, item 6).

    PYTHONPATH=src python docs/measure_handover_transition.py [--trials 20] [--transition-data CSV]
        [--passive PKL ...]

For the near and far goals: the transition distance T the handover predicts (:class:`TransitionModel` on the
shipped planar data, or on --transition-data, e.g. made by ``comanip transition generate --preset
cartesian``), the distance at which the robot released, the peak of the perpendicular spread of the handle
paths in the handover run, and the same peak for the person alone (a passive robot in the sync scenario,
same seeds: the person's own transition; --passive reuses pickles written by
``docs/make_policy_comparison.py --save``). Writes docs/handover_transition.md.
"""

from __future__ import annotations

import argparse
import pickle
from pathlib import Path

import numpy as np

from comanip.multicomponent.dispersion import perpendicular_dispersion_profile
from comanip.multicomponent.transition_model import TransitionModel
from comanip.simulation import HandoverSettings, ScenarioSetup, SyncSettings, run_handover, run_sync

DOCS = Path(__file__).resolve().parent
GOALS = ("near", "far")


def spread_peak(paths: np.ndarray, goal: np.ndarray) -> tuple[float, float]:
    """(distance of the perpendicular spread's peak from the goal (m), the peak spread (m)) of paths (N, K, 3)."""
    profile = perpendicular_dispersion_profile(paths, goal)
    return profile.transition_distance, profile.peak_dispersion


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=20, help="trials per goal (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--transition-data", type=Path, help="transition CSV for the TransitionModel (default: shipped)")
    parser.add_argument("--passive", type=Path, nargs="*", help="pickles of make_policy_comparison.py --save to reuse")
    args = parser.parse_args(argv)
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
    command = f"PYTHONPATH=src python docs/measure_handover_transition.py --trials {args.trials}" + \
              (f" --transition-data {args.transition_data}" if args.transition_data else "")
    text = f"Distances from the goal; measured by `{command}` (seeds {args.seed}–{args.seed + args.trials - 1}).\n\n{table}"
    suffix = "" if args.transition_data is None else "_" + args.transition_data.stem
    (DOCS / f"handover_transition{suffix}.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
