"""Print the calibration-study block of docs/results/calibration.md: every configuration of the planar preset's family over the
Fitts grid, with its t_peak/MT range, movement times, Fitts and Shannon R², and the two verdicts.

    PYTHONPATH=src python -m studies.does_any_paper_configuration_peak_early.print_calibration_study [--workers N] [--seed 0]

The same study, settings and rows as ``comanip validate`` (full run; ``report.md``, "Calibration study"),
as a shorter table; the verdicts' definitions are in :mod:`comanip.analysis.calibration`.
"""

from __future__ import annotations

import argparse
import sys
import time

from comanip import presets
from comanip.analysis.calibration import run_calibration, study_configurations
from comanip.validation.run_settings import ValidationSettings


LABELS = ("Labels: W=std reads W = w²I, W=cov W = wI; iso, chan, rank1: isotropic, per-channel, rank-one noise; "
          "exp, hyp: exponential, hyperbolic discounting; H: horizon (steps); then any other change.")


def study_block(rows: list[dict], settings: ValidationSettings, seconds: float) -> str:
    lines = ["| configuration | mode | t_peak/MT min / median / max | MT (s) | R² Fitts / Shannon | Fitts' law | early peak |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['configuration']} | {r['mode']} | {r['asymmetry_min']:.2f} / {r['asymmetry_median']:.2f} / "
                     f"{r['asymmetry_max']:.2f} | {r['mt_min_s']:.2f}–{r['mt_max_s']:.2f} | {r['fitts_r2']:.3f} / "
                     f"{r['shannon_r2']:.3f} | {'yes' if r['fitts_law'] else 'no'} | {'yes' if r['early_peak'] else 'no'} |")
    both = [r["configuration"] for r in rows if r["both"]]
    return (f"Measured by `studies/does_any_paper_configuration_peak_early/print_calibration_study.py` ({len(rows)} configurations; D ∈ {list(settings.distances)} m × "
            f"w ∈ {list(settings.widths)} m; closed loop: {settings.calibration_trials} executions per condition; seed "
            f"{settings.seed}; {seconds:.0f} s). Configurations with Fitts' law and an early peak at once: "
            f"{', '.join(both) if both else '**none**'}. {LABELS}\n\n" + "\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, help="processes (default: the CPU count)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    settings = ValidationSettings(seed=args.seed, workers=args.workers, franka=False)
    began = time.perf_counter()
    results = run_calibration(presets.planar(), study_configurations(), settings.distances, settings.widths,
                              n_trials=settings.calibration_trials, seed=settings.seed, workers=settings.workers)
    print(study_block([result.summary() for result in results], settings, time.perf_counter() - began))
    return 0


if __name__ == "__main__":
    sys.exit(main())
