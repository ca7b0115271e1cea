"""Do the presets move like people? Recorded mouse movements (the cursory development split, at arm scale)
against the presets' mean reaches: when the speed peaks (t_peak / MT), how long a movement of a given
distance takes (MT against D), and the speed profile normalised in time and amplitude.

    PYTHONPATH=src python -m studies.do_the_presets_move_like_people.compare [--markdown]

Writes ``speed_profiles.png`` and ``comparison.json`` beside this script; prints the markdown table.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
PRESETS = ("planar", "human", "people", "cartesian", "human_cartesian")
BINS = ((0.1, 0.2), (0.2, 0.3), (0.3, 0.45), (0.45, 0.7))
PHASE = np.linspace(0, 1, 101)


def normalised_speed(t, speed, onset, end):
    """Speed over its peak (P,) at PHASE of the movement from onset to end (s)."""
    return np.interp(onset + PHASE * (end - onset), t, speed) / speed.max()


def people(recordings):
    peaks, MT, D, profiles = [], [], [], []
    for r in recordings:
        speed = np.linalg.norm(r.velocity, axis=1)
        inside = r.t >= r.onset - 1e-9
        peak = r.t[inside][int(np.argmax(speed[inside]))]
        peaks.append((peak - r.onset) / r.movement_time)
        MT.append(r.movement_time)
        D.append(r.distance)
        profiles.append(normalised_speed(r.t, speed, r.onset, r.end_time))
    return np.array(peaks), np.array(MT), np.array(D), np.array(profiles)


def preset_reaches(name):
    import comanip
    from comanip.recordings.preprocessing import movement_bounds

    model = comanip.presets.load(name)
    planner = comanip.Planner(model)
    rows = []
    for D in (0.15, 0.25, 0.33, 0.5, 0.65):
        goal = np.r_[D, np.zeros(model.n - 1)]
        plan = planner.solve(np.zeros(model.state_size), goal, model.width)
        onset, end = movement_bounds(plan.t, plan.ee_velocity)
        peak = plan.t[int(np.argmax(plan.ee_speed))]
        rows.append({"D": D, "MT": end - onset, "peak": (peak - onset) / (end - onset), "status": str(plan.status),
                     "profile": normalised_speed(plan.t, plan.ee_speed, onset, end)})
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--markdown", action="store_true", help="print only the table")
    args = parser.parse_args(argv)
    from comanip.recordings import load_cursory

    log = sys.stderr if args.markdown else sys.stdout
    recordings = load_cursory("development")
    peaks, MT, D, profiles = people(recordings)
    print(f"{len(recordings)} recorded movements", file=log)
    slope, intercept = np.polyfit(np.log(D), np.log(MT), 1)
    rows = [("recorded people (cursory development split)", f"{np.median(peaks):.2f} [{np.percentile(peaks, 25):.2f}–{np.percentile(peaks, 75):.2f}]",
             [np.median(MT[(D >= lo) & (D < hi)]) for lo, hi in BINS], slope)]
    presets = {}
    for name in PRESETS:
        reaches = preset_reaches(name)
        presets[name] = reaches
        mts = [np.interp(np.sqrt(lo * hi), [r["D"] for r in reaches], [r["MT"] for r in reaches]) for lo, hi in BINS]
        b = np.polyfit(np.log([r["D"] for r in reaches]), np.log([r["MT"] for r in reaches]), 1)[0]
        peak = [r["peak"] for r in reaches]
        rows.append((f"`{name}` preset (mean reach)", f"{np.median(peak):.2f} [{min(peak):.2f}–{max(peak):.2f}]", mts, b))
    lines = ["| who | t_peak / MT, median [IQR; presets: range over D] | " + " | ".join(f"MT (s), D {lo}–{hi} m" for lo, hi in BINS)
             + " | d log MT / d log D |", "|---|---|" + "---|" * len(BINS) + "---|"]
    for who, peak, mts, b in rows:
        lines.append(f"| {who} | {peak} | " + " | ".join(f"{m:.2f}" for m in mts) + f" | {b:.2f} |")
    table = "\n".join(lines)
    print(table)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.fill_between(PHASE, np.percentile(profiles, 25, axis=0), np.percentile(profiles, 75, axis=0), color="0.8",
                    label="recorded people, IQR")
    ax.plot(PHASE, np.median(profiles, axis=0), color="k", lw=2, label="recorded people, median")
    for name, reaches in presets.items():
        middle = min(reaches, key=lambda r: abs(r["D"] - 0.33))
        ax.plot(PHASE, middle["profile"], label=f"{name} preset, D = 0.33 m")
    ax.set_xlabel("time / MT (from onset)")
    ax.set_ylabel("speed / peak speed")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "speed_profiles.png", dpi=120)
    fig.savefig(HERE.parents[1] / "docs" / "figures" / "speed_profiles_people_presets.png", dpi=120)
    (HERE / "comparison.json").write_text(json.dumps({
        "people": {"movements": len(recordings), "peak_fraction_median": float(np.median(peaks)),
                   "mt_log_slope": float(slope), "mt_log_intercept": float(intercept)},
        "presets": {name: [{k: v for k, v in r.items() if k != "profile"} for r in reaches] for name, reaches in presets.items()},
    }, indent=1))
    print(f"wrote {HERE / 'speed_profiles.png'}", file=log)


if __name__ == "__main__":
    main()
