"""Does the arm preset move like recorded arms? Its mean reach against motion-capture arm reaches.

People: every reach of a TAT-HUM 3-D data folder (default: the development split beside the repository),
preprocessed by :meth:`comanip.recordings.TrackedSamples.recording` (4 ms grid, Savitzky–Golay velocities,
onset and end at 5 % of the peak speed): movement time MT, t_peak / MT, peak speed, endpoint spread (SD of
the endpoints of each target's reaches, per axis, pooled). Model: the preset's mean reach from rest over
the people's median distance, with the width its YAML gives, timed as the recordings are cut
(:func:`comanip.analysis.movement_timing`), twice: its plan (open loop, what the online estimator's reach family holds) and its closed loop (the mean of
``--trials`` executions that replan every step from what the person sees, 100 ms late: the fast first
sub-movement and the corrections after it); the endpoint SD from the plan's covariance at MT and over the
closed-loop executions at their end; Fitts' law of the plans on the validation grid (D 0.15–0.45 m × w
0.005–0.04 m). Prints a markdown table and writes a figure of the speed profiles,
normalised in time (by MT, from the onset) and amplitude (by the peak), the model over the people's
10–90 % band.

``--people``: the same timing person by person on the eleven recorded arm people (TAT-HUM's and UE_ADL's ten,
read as benchmarks/forecast_peers.py reads them), each against the preset's closed loop over that person's median
distance: does the timing the preset was fitted to (one person at 0.22 m) carry to people it was not fitted on?

    PYTHONPATH=src python -m studies.does_the_arm_preset_move_like_recorded_arms.compare [--preset arm] [--figure PATH]
    PYTHONPATH=src python -m studies.does_the_arm_preset_move_like_recorded_arms.compare --people [--trials 8]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import comanip
from comanip.analysis.fitts import fit_fitts
from comanip.analysis.speed_profile import movement_timing, speed_metrics
from comanip.execution import execute_receding_horizon
from comanip.recordings import load_tathum

ARMS = Path(__file__).resolve().parents[3] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
PHASE = np.linspace(0.0, 1.0, 51)


def people(folder: Path) -> dict:
    trials = load_tathum(folder)
    return recorded_metrics(trials, [trial.recording() for trial in trials])


def recorded_metrics(trials, recordings) -> dict:
    """The people's quantities (module docstring) of ``recordings``, the preprocessed ``trials`` (their labels name
    each reach's target)."""
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
    deviation, angle = [], []
    for r in recordings:
        moving = (r.t >= r.onset) & (r.t <= r.end_time)
        offset = r.position[moving] - r.start
        line = (r.end - r.start) / r.distance
        across = offset - np.outer(offset @ line, line)
        deviation.append(np.sqrt((across * across).sum(axis=1)).max() / r.distance)
        early = offset[int(np.searchsorted(offset @ line, 0.1 * r.distance))]     # where a tenth of the way is covered
        angle.append(np.degrees(np.arccos(np.clip(early @ line / np.linalg.norm(early), -1.0, 1.0))))
    return {"count": len(recordings), "distance": np.array([r.distance for r in recordings]),
            "deviation": np.array(deviation), "angle": np.array(angle),
            "movement_time": np.array([r.movement_time for r in recordings]), "asymmetry": np.array(asymmetry),
            "peak_speed": np.array(peaks), "profiles": np.array(profiles),
            "endpoint_sd": float(np.sqrt(np.mean(spread)))}


def timing(t: np.ndarray, speed: np.ndarray) -> dict:
    """MT, t_peak / MT and the normalised profile of a mean speed profile, timed as recorded movements are cut."""
    metrics = movement_timing(t, speed)
    return {"movement_time": metrics.movement_time, "asymmetry": metrics.peak_fraction, "peak_speed": metrics.peak_speed,
            "profile": np.interp(metrics.onset + PHASE * metrics.movement_time, t, speed) / metrics.peak_speed}


def closed_loop(model, distance: float, trials: int) -> tuple[dict, list]:
    """(the timing (:func:`timing`) of their mean, the executions) of ``trials`` closed-loop executions of the
    preset's reach over ``distance`` (m)."""
    planner = comanip.Planner(model)
    start, goal, rng = np.zeros(model.state_size), np.array([distance, 0.0, 0.0]), np.random.default_rng(0)
    runs = [execute_receding_horizon(planner, start, goal, model.width, steps=2 * model.H, rng=rng) for _ in range(trials)]
    return timing(runs[0].t, np.linalg.norm(np.mean([run.ee_velocity for run in runs], axis=0), axis=1)), runs


def model_reach(model, distance: float, trials: int) -> dict:
    planner = comanip.Planner(model)
    start = np.zeros(model.state_size)
    goal = np.array([distance, 0.0, 0.0])
    plan = planner.solve(start, goal, model.width)
    planned = timing(plan.t, plan.ee_speed)
    at_mt = int(np.searchsorted(plan.t, speed_metrics(plan.t, plan.ee_speed).movement_time))
    planned["endpoint_sd"] = float(np.sqrt(np.trace(plan.ee_cov[at_mt]) / model.d))
    closed, runs = closed_loop(model, distance, trials)
    closed["endpoint_sd"] = float(np.sqrt(np.mean(np.var([run.ee[-1] for run in runs], axis=0))))
    grid = [(D, w, speed_metrics(*(lambda p: (p.t, p.ee_speed))(planner.solve(start, [D, 0.0, 0.0], w))).movement_time)
            for D in (0.15, 0.3, 0.45) for w in (0.005, 0.01, 0.02, 0.04)]
    return {"plan": planned, "closed": closed, "fitts": fit_fitts(*map(np.array, zip(*grid)))}


def by_person(preset: str, trials: int) -> None:
    """The --people table (module docstring), with the share of people whose median MT the preset's is within
    10 % of and whose IQR of t_peak / MT holds the preset's."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from forecast_peers import TATHUM, UE_ADL, people_trials  # noqa: E402  (the reaches the arm-people blocks score)
    people = people_trials(TATHUM, UE_ADL)
    model = comanip.presets.load(preset)
    print(f"The `{preset}` preset's closed loop ({trials} executions) over each recorded arm person's median distance, "
          "against the person's reaches: median [IQR]\n")
    print("| person | reaches | distance (m) | MT (s): people; preset | t_peak / MT: people; preset | "
          "peak speed (m/s): people; preset |\n|---|---|---|---|---|---|")
    within, inside = 0, 0
    q = lambda x: f"{np.median(x):.3g} [{np.percentile(x, 25):.3g}–{np.percentile(x, 75):.3g}]"
    for person, reaches in people.items():
        recorded = recorded_metrics(reaches, [trial.recording() for trial in reaches])
        D = float(np.median(recorded["distance"]))
        closed, _ = closed_loop(model, D, trials)
        mt = float(np.median(recorded["movement_time"]))
        low, high = np.percentile(recorded["asymmetry"], [25, 75])
        within += abs(closed["movement_time"] / mt - 1) <= 0.1
        inside += low <= closed["asymmetry"] <= high
        print(f"| {person} | {recorded['count']} | {D:.3f} | {q(recorded['movement_time'])}; {closed['movement_time']:.3f} | "
              f"{q(recorded['asymmetry'])}; {closed['asymmetry']:.3f} | {q(recorded['peak_speed'])}; "
              f"{closed['peak_speed']:.3f} |")
    count = len(people)
    print(f"\nThe preset's MT within 10 % of the person's median for {within} of {count} people; its t_peak / MT inside "
          f"the person's IQR for {inside} of {count}.")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--arms", type=Path, default=ARMS, help="a TAT-HUM 3-D data folder")
    parser.add_argument("--preset", default="arm")
    parser.add_argument("--trials", type=int, default=32, help="closed-loop executions averaged")
    parser.add_argument("--figure", type=Path, default=None)
    parser.add_argument("--people", action="store_true", help="person by person on the eleven arm people (module docstring)")
    args = parser.parse_args(argv)
    if args.people:
        return by_person(args.preset, args.trials)
    recorded = people(args.arms)
    model = comanip.presets.load(args.preset)
    D = float(np.median(recorded["distance"]))
    mine = model_reach(model, D, args.trials)
    q = lambda x: f"{np.median(x):.3g} [{np.percentile(x, 25):.3g}–{np.percentile(x, 75):.3g}]"
    mt = float(np.median(recorded["movement_time"]))
    low, high = np.percentile(recorded["asymmetry"], [25, 75])
    plan, closed, fitts = mine["plan"], mine["closed"], mine["fitts"]
    met = lambda ok: "yes" if ok else "no"
    print(f"Recorded arm reaches ({recorded['count']}, median distance {D:.3f} m) against the `{args.preset}` preset's "
          f"mean reach over that distance (width {model.width:g} m; closed loop: {args.trials} executions): "
          f"people median [IQR]\n")
    print("| quantity | people | plan | closed loop | target | met (closed loop) |\n|---|---|---|---|---|---|")
    print(f"| movement time (s) | {q(recorded['movement_time'])} | {plan['movement_time']:.3f} | {closed['movement_time']:.3f} | "
          f"within 10 % of {mt:.3f} | {met(abs(closed['movement_time'] / mt - 1) <= 0.1)} |")
    print(f"| t_peak / MT | {q(recorded['asymmetry'])} | {plan['asymmetry']:.3f} | {closed['asymmetry']:.3f} | "
          f"inside {low:.3f}–{high:.3f} | {met(low <= closed['asymmetry'] <= high)} |")
    print(f"| peak speed (m/s) | {q(recorded['peak_speed'])} | {plan['peak_speed']:.3f} | {closed['peak_speed']:.3f} | | |")
    print(f"| endpoint SD per axis (mm) | {1e3 * recorded['endpoint_sd']:.2f} | {1e3 * plan['endpoint_sd']:.2f} (at MT) | "
          f"{1e3 * closed['endpoint_sd']:.2f} | | |")
    print(f"| path's largest distance from the straight line, / D | {q(recorded['deviation'])} | 0 | 0 | | |")
    print(f"| angle to the straight line a tenth of the way (°) | {q(recorded['angle'])} | 0 | 0 | | |")
    print(f"| Fitts' law on the validation grid (plans) | | slope {1e3 * fitts.b:.0f} ms/bit, R² {fitts.r2:.3f} | | "
          f"80–160 ms/bit, R² ≥ 0.95 | {met(0.08 <= fitts.b <= 0.16 and fitts.r2 >= 0.95)} |")
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.6))
        band = np.percentile(recorded["profiles"], [10, 50, 90], axis=0)
        ax.fill_between(PHASE, band[0], band[2], color="0.8", label="people, 10–90 %")
        ax.plot(PHASE, band[1], color="0.3", label="people, median")
        ax.plot(PHASE, plan["profile"], color="C3", ls="--", label=f"{args.preset} preset, plan")
        ax.plot(PHASE, closed["profile"], color="C3", label=f"{args.preset} preset, closed loop (mean)")
        ax.set_xlabel("time since the onset / MT")
        ax.set_ylabel("speed / peak speed")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.figure, dpi=120)
        print(f"\nwrote {args.figure}")


if __name__ == "__main__":
    main()
