"""Print the results page's block on Peternel & Babič's trends: the shipped transition data and the GP fitted to it.

    PYTHONPATH=src python -m studies.are_the_published_transition_trends_reproduced.print_transition_trends [--data transition.csv]

The same numbers as ``comanip transition fit`` writes to ``trends.json`` (:func:`comanip.multicomponent.trends.trend_report`),
as a markdown table.
"""

from __future__ import annotations

import argparse
import sys

from comanip.multicomponent.transition_csv import shipped_dataset_path
from comanip.multicomponent.transition_model import TransitionModel
from comanip.multicomponent.trends import trend_report

#: how each output column reads in the table, and the factor from its unit (m) to the table's
_SCALE = {"transition_distance_m": ("m", 1.0), "peak_dispersion_m": ("mm", 1e3)}


def data_cell(trend: dict) -> str:
    """'+0.397 m per unit D/L [0.373, 0.421]' (slope and 95 % CI) and, per m of width, the change over the data's range."""
    data = trend["data"]
    if data is None or data["slope"] is None:
        return "–"
    unit, scale = _SCALE[trend["output"]]
    per = "unit D/L" if trend["input"] == "distance_over_arm_length" else "m of w"
    low, high = (scale * v for v in data["slope_ci95"])
    return (f"{scale * data['slope']:+.3g} {unit} per {per} [{low:.2g}, {high:.2g}]; "
            f"{scale * data['change_over_range']:+.2g} {unit} over the data's range")


def model_cell(trend: dict) -> str:
    """The GP mean's change over the data's range of the input, ± its posterior std."""
    model = trend["model"]
    if model is None:
        return "–"
    unit, scale = ("mm", 1e3) if abs(model["change_over_range"]) < 0.01 else ("m", 1.0)
    low, high = model["range"]
    over = f"D/L {low:g}–{high:g}" if trend["input"] == "distance_over_arm_length" else f"w {low:g}–{high:g} m"
    return f"{scale * model['change_over_range']:+.3g} ± {scale * model['std']:.2g} {unit} over {over}"


def trends_block(report: dict, data_name: str) -> str:
    rows = ["| published trend | shipped data: OLS slope [95 % CI] | fitted model | verdict (data / model) |",
            "|---|---|---|---|"]
    for trend in report["trends"]:
        verdicts = [trend["data"]["verdict"] if trend["data"] else "–", trend["model"]["verdict"] if trend["model"] else "–"]
        verdict = " / ".join(v if v == "reproduced" or v == "–" else f"**{v}**" for v in verdicts)
        rows.append(f"| {trend['claim']} | {data_cell(trend)} | {model_cell(trend)} | {verdict} |")
    return (f"Measured by `studies/are_the_published_transition_trends_reproduced/print_transition_trends.py` on `{data_name}` ({report['rows']} rows): "
            f"{report['method']}\n\n" + "\n".join(rows))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", help="transition CSV (default: the shipped dataset)")
    args = parser.parse_args(argv)
    data = args.data or shipped_dataset_path()
    name = args.data or "src/comanip/data/" + shipped_dataset_path().name
    print(trends_block(trend_report(TransitionModel(data)), name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
