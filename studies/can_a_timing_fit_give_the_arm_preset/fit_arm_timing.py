"""Can a fit give the arm preset? The timing fit on recorded arms, and what the fitted models' reaches do.

First the fit on reaches the model itself executed (the planar preset at kappa 0.02, closed loop, 3 goals × 12
reaches; from kappa 0.008), to show it recovers what made the data. Then ``comanip.fit_timing`` on a TAT-HUM 3-D data
folder (default: the arm development split beside the repository) from ``START``, the `arm` preset's body with two
muscle stages, kappa 0.012 and an 8 mm goal, with the free parameters and goal widths of each row; the last row is
the fit that gives the `arm` preset. Each fitted model (and the preset as it is) is then measured as
``studies/does_the_arm_preset_move_like_recorded_arms`` measures the preset: its mean closed-loop reach over the people's
median distance (``EXECUTIONS`` of them) against the people's median MT and t_peak/MT IQR, and Fitts' law of its plans on the
validation grid. Prints a markdown table.

    PYTHONPATH=src python -m studies.can_a_timing_fit_give_the_arm_preset.fit_arm_timing [--arms FOLDER]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import comanip
from comanip.execution import execute_receding_horizon
from comanip.fitting import Trial, fit_timing
from comanip.recordings import load_tathum
from comanip.recordings.trial_files import tracked_trials
from studies.does_the_arm_preset_move_like_recorded_arms.compare import ARMS, model_reach, people

EXECUTIONS = 96
"""Closed-loop executions in a measured model's mean reach: its t_peak/MT scatters by a few hundredths over 8."""

START_CHANGES = {"kappa": 0.012, "activation": (0.04, 0.04), "width": 0.008}
"""What the model the fits start from changes in the `arm` preset: two muscle stages (activation and force), kappa, width (m)."""

#: (free parameters, goal width of every trial in m or None for the recordings' endpoint spread, changes to ``START``
#: the fit starts from)
ARM_FITS = ((("kappa", "gamma"), None, {}), (("kappa", "activation.0"), None, {}), (("kappa", "gamma"), 0.008, {}),
            (("kappa",), 0.008, {}), (("kappa", "activation.0"), 0.006, {}), (("kappa",), 0.006, {"activation": (0.04,)}))


def synthetic_row() -> str:
    """The fit on the planar preset's own closed-loop reaches."""
    truth = comanip.presets.planar().replace(kappa=0.02)
    planner = comanip.Planner(truth)
    trials = []
    for g, (goal, width) in enumerate((((0.3, 0.0), 0.02), ((0.15, 0.15), 0.01), ((0.2, -0.1), 0.03))):
        for k in range(12):
            run = execute_receding_horizon(planner, np.zeros(4), goal, width, steps=2 * truth.H, rng=np.random.default_rng([1000 + g, k]))
            trials.append(Trial(f"g{g}-{k}", run.t, run.ee, np.array(goal), width))
    fit = fit_timing(truth.replace(kappa=0.008), trials, ["kappa"], progress=False)
    return (f"| planar preset's own reaches (kappa 0.02), kappa from 0.008 | as given | {fit.status}: {_values(fit)} | "
            f"{fit.objective:.1f} / {2 * 3 - 1} | {fit.evaluations}, {fit.fit_time:.0f} s | | | | |")


def _values(fit) -> str:
    return ", ".join(f"{name} {value:.4g} ± {fit.std_errors[name]:.2g}" for name, value in fit.values.items())


def measured(model, recorded: dict) -> tuple[str, bool]:
    """The row's measured columns for a model, and whether it meets every target."""
    D = float(np.median(recorded["distance"]))
    mine = model_reach(model, D, EXECUTIONS)
    closed, fitts = mine["closed"], mine["fitts"]
    mt = float(np.median(recorded["movement_time"]))
    low, high = np.percentile(recorded["asymmetry"], [25, 75])
    checks = (abs(closed["movement_time"] / mt - 1) <= 0.1, low <= closed["asymmetry"] <= high,
              0.08 <= fitts.b <= 0.16 and fitts.r2 >= 0.95)
    return (f"{closed['movement_time']:.3f} | {closed['asymmetry']:.3f} | {1e3 * fitts.b:.0f} ms/bit, R² {fitts.r2:.3f} | "
            f"{' / '.join('yes' if ok else 'no' for ok in checks)}"), all(checks)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--arms", type=Path, default=ARMS, help="a TAT-HUM 3-D data folder")
    args = parser.parse_args(argv)
    recorded, trials = people(args.arms), tracked_trials(load_tathum(args.arms))
    preset = comanip.presets.arm()
    start_model = preset.replace(**START_CHANGES)
    mt = float(np.median(recorded["movement_time"]))
    low, high = np.percentile(recorded["asymmetry"], [25, 75])
    print(f"The timing fit (`comanip fit --match timing`, 8 executions per mean reach) on the model's own reaches and on "
          f"the recorded arm reaches ({recorded['count']}; 2 targets), from the `arm` body with two muscle stages (kappa "
          f"{start_model.kappa:g}, gamma {start_model.gamma:g}, activation {', '.join(f'{a:g}' for a in start_model.activation)} s, "
          f"width {start_model.width:g} m); each model's mean "
          f"closed-loop reach over {float(np.median(recorded['distance'])):.3f} m ({EXECUTIONS} executions) at its width, against "
          f"the people's median MT {mt:.3f} s (within 10 %) and t_peak/MT IQR {low:.3f}–{high:.3f}, and Fitts' law of its "
          f"plans on the validation grid (80–160 ms/bit, R² ≥ 0.95)\n")
    print("| fit | goal widths | fitted ± SE | chi² / dof | evaluations, time | mean reach MT (s) | t_peak / MT | Fitts' law | "
          "MT / t_peak / Fitts met |\n|---|---|---|---|---|---|---|---|---|")
    print(synthetic_row(), flush=True)
    for name, model in (("the start, two muscle stages (no fit)", start_model), ("the `arm` preset (no fit)", preset)):
        row, _ = measured(model, recorded)
        print(f"| {name} | {model.width:g} m | | | | {row} |", flush=True)
    for parameters, width, changes in ARM_FITS:
        fit = fit_timing(start_model.replace(**changes), trials, parameters, width=width, progress=False)
        used = fit.model.replace(width=float(np.mean([c["width_m"] for c in fit.conditions])))
        row, _ = measured(used, recorded)
        widths = "recorded endpoint spread" if width is None else f"{width:g} m"
        start = "".join(f" ({name} {value})" for name, value in changes.items())
        print(f"| arm reaches, {', '.join(parameters)}{start} | {widths} ({used.width:.4f} m) | {fit.status}: {_values(fit)} | "
              f"{fit.objective:.1f} / {2 * len(fit.conditions) - len(parameters)} | {fit.evaluations}, {fit.fit_time:.0f} s | {row} |",
              flush=True)


if __name__ == "__main__":
    main()
