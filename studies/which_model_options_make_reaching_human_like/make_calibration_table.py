"""Print the human-likeness block of docs/results/calibration.md from a fresh measurement (``tools/regenerate_results.py
human-targets`` puts it on its results page).

    PYTHONPATH=src python -m studies.which_model_options_make_reaching_human_like.make_calibration_table [PRESET ...] [--samples 2000] [--seed 0] [--trials 20]

Scores each preset (a built-in name or a model YAML; default: ``human`` when that preset exists, then
``planar``) on the human-likeness targets (:func:`comanip.analysis.measure_human_targets`, the grid
D ∈ {0.15, 0.3, 0.45} m × w ∈ {0.005, 0.01, 0.02, 0.04} m) and prints how it was measured and the verdict
table, the presets side by side, as ``comanip validate`` reports it.
"""

from __future__ import annotations

import argparse
import sys
import time

from comanip import presets
from comanip.analysis import measure_closed_loop_targets, measure_human_targets
from comanip.validation.human_section import human_section
from comanip.validation.markdown import verdict_table

def measured_block(names: list[str], samples: int, seed: int, trials: int) -> str:
    """The block's markdown: how it was measured, the definition of w and ID, and the verdict table."""
    began = time.perf_counter()
    results = []
    for name in names:
        model = presets.load(name)
        results.append(measure_human_targets(model, n_samples=samples, seed=seed))
        if model.observation:  # a model with feedback is scored on its closed loop too
            results.append(measure_closed_loop_targets(model, trials, seed=seed))
    section = human_section(results)
    command = " ".join(["studies/which_model_options_make_reaching_human_like/make_calibration_table.py", *names, f"--trials {trials}"])
    return (f"Measured by `{command}` ({samples} open-loop Monte Carlo executions per condition; {trials} closed-loop "
            f"executions per condition for a model with feedback (`observation`), scored on their mean velocity and "
            f"their hands at MT; seed {seed}; {time.perf_counter() - began:.0f} s for planning, executing and scoring): "
            f"{section['definition']}.\n\n{verdict_table(section)}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("presets", nargs="*", help="presets or model YAML files (default: human if it exists, then planar)")
    parser.add_argument("--samples", type=int, default=2000, help="Monte Carlo executions per condition (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the Monte Carlo draws (default: %(default)s)")
    parser.add_argument("--trials", type=int, default=20,
                        help="closed-loop executions per condition of a model with feedback (default: %(default)s)")
    args = parser.parse_args(argv)
    names = args.presets or [name for name in ("human", "planar") if name in presets.names()]
    print(measured_block(names, args.samples, args.seed, args.trials))
    return 0


if __name__ == "__main__":
    sys.exit(main())
