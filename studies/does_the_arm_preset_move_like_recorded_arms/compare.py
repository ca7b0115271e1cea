"""Does the arm preset move like recorded arms? Its mean reach against motion-capture arm reaches.

People: every reach of a TAT-HUM 3-D data folder (default: the development split beside the repository),
preprocessed by :meth:`comanip.recordings.TrackedSamples.recording` (4 ms grid, Savitzky–Golay velocities,
onset and end at 5 % of the peak speed): movement time MT, t_peak / MT, peak speed, endpoint spread (SD of
the endpoints of each target's reaches, per axis, pooled). Model: the preset's mean reach (its plan) from
rest over the people's median distance, with the width its YAML gives, timed the same way
(docs/formulation.md §6); its endpoint SD from the plan's covariance at MT; Fitts' law on the validation grid
(D 0.15–0.45 m × w 0.005–0.04 m). Prints a markdown table and writes a figure of the speed profiles,
normalised in time (by MT, from the onset) and amplitude (by the peak), the model over the people's
10–90 % band.

    PYTHONPATH=src python studies/does_the_arm_preset_move_like_recorded_arms/compare.py [--preset arm] [--figure PATH]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import comanip
from comanip.analysis.fitts import fit_fitts
from comanip.analysis.speed_profile import speed_metrics
from comanip.recordings import load_tathum

ARMS = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
PHASE = np.linspace(0.0, 1.0, 51)


def people(folder: Path) -> dict:
    trials = load_tathum(folder)
    recordings = [trial.recording() for trial in trials]
    asymmetry, profiles, peaks = [], [], []
    for r in recordings:
        speed = np.linalg.norm(r.velocity, axis=1)
        k = int(np.argmax(speed))
        asymmetry.append((r.t[k] - r.onset) / r.movement_time)
        peaks.append(speed[k])
        profiles.append(np.interp(r.onset + PHASE * r.movement_time, r.t, speed) / speed[k])
    spread = []
    for target in {t.label["target"] for t in trials}:
        ends = np.array([r.end for r, t in zip(recordings, trials) if t.label["target"] == target])
        spread.append(ends.var(axis=0))
    return {"count": len(recordings), "distance": np.array([r.distance for r in recordings]),
            "movement_time": np.array([r.movement_time for r in recordings]), "asymmetry": np.array(asymmetry),
            "peak_speed": np.array(peaks), "profiles": np.array(profiles),
            "endpoint_sd": float(np.sqrt(np.mean(spread)))}


def model_reach(model, distance: float) -> dict:
    planner = comanip.Planner(model)
    start = np.zeros(model.state_size)
    plan = planner.solve(start, [distance, 0.0, 0.0], model.width)
    metrics = speed_metrics(plan.t, plan.ee_speed)
    onset = plan.t[int(np.argmax(plan.ee_speed > 0.05 * metrics.peak_speed))]
    profile = np.interp(onset + PHASE * (metrics.movement_time - onset), plan.t, plan.ee_speed) / metrics.peak_speed
    at_mt = int(np.searchsorted(plan.t, metrics.movement_time))
    endpoint_sd = float(np.sqrt(np.trace(plan.ee_cov[at_mt]) / model.d))
    grid = [(D, w, speed_metrics(*(lambda p: (p.t, p.ee_speed))(planner.solve(start, [D, 0.0, 0.0], w))).movement_time)
            for D in (0.15, 0.3, 0.45) for w in (0.005, 0.01, 0.02, 0.04)]
    fitts = fit_fitts(*map(np.array, zip(*grid)))
    return {"movement_time": metrics.movement_time - onset, "asymmetry": (metrics.t_peak - onset) / (metrics.movement_time - onset),
            "peak_speed": metrics.peak_speed, "profile": profile, "endpoint_sd": endpoint_sd, "fitts": fitts,
            "success": plan.success}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--arms", type=Path, default=ARMS, help="a TAT-HUM 3-D data folder")
    parser.add_argument("--preset", default="arm")
    parser.add_argument("--figure", type=Path, default=None)
    args = parser.parse_args(argv)
    recorded = people(args.arms)
    model = comanip.presets.load(args.preset)
    D = float(np.median(recorded["distance"]))
    mine = model_reach(model, D)
    q = lambda x: f"{np.median(x):.3g} [{np.percentile(x, 25):.3g}–{np.percentile(x, 75):.3g}]"
    mt = float(np.median(recorded["movement_time"]))
    low, high = np.percentile(recorded["asymmetry"], [25, 75])
    fitts = mine["fitts"]
    print(f"Recorded arm reaches ({recorded['count']}, median distance {D:.3f} m) against the `{args.preset}` preset's "
          f"mean reach over that distance (width {model.width:g} m): median [IQR]\n")
    print("| quantity | people | model | target | met |\n|---|---|---|---|---|")
    print(f"| movement time (s) | {q(recorded['movement_time'])} | {mine['movement_time']:.3f} | within 10 % of {mt:.3f} | "
          f"{'yes' if abs(mine['movement_time'] / mt - 1) <= 0.1 else 'no'} |")
    print(f"| t_peak / MT | {q(recorded['asymmetry'])} | {mine['asymmetry']:.3f} | inside {low:.3f}–{high:.3f} | "
          f"{'yes' if low <= mine['asymmetry'] <= high else 'no'} |")
    print(f"| peak speed (m/s) | {q(recorded['peak_speed'])} | {mine['peak_speed']:.3f} | | |")
    print(f"| endpoint SD per axis (mm) | {1e3 * recorded['endpoint_sd']:.2f} | {1e3 * mine['endpoint_sd']:.2f} (open loop, at MT) | | |")
    print(f"| Fitts' law on the validation grid | | slope {1e3 * fitts.b:.0f} ms/bit, R² {fitts.r2:.3f} | 80–160 ms/bit, R² ≥ 0.95 | "
          f"{'yes' if 0.08 <= fitts.b <= 0.16 and fitts.r2 >= 0.95 else 'no'} |")
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.6))
        band = np.percentile(recorded["profiles"], [10, 50, 90], axis=0)
        ax.fill_between(PHASE, band[0], band[2], color="0.8", label="people, 10–90 %")
        ax.plot(PHASE, band[1], color="0.3", label="people, median")
        ax.plot(PHASE, mine["profile"], color="C3", label=f"{args.preset} preset, mean reach")
        ax.set_xlabel("time since the onset / MT")
        ax.set_ylabel("speed / peak speed")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=120)
        print(f"\nwrote {args.figure}")


if __name__ == "__main__":
    main()
