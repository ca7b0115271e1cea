"""Calibration over a person's successive reaches: does what the online estimator learns of a person from their
finished reaches (:mod:`comanip.estimation.calibration.person_calibration`) carry it to people it was not fitted on?

People it has not met, made from what the repository has (the development arm reaches of one person, and the
reaching model's own reaches):

- ``arm``: the development arm reaches in blocks of ``--reaches`` successive reaches, each block one person,
  played at a pace drawn from ×0.6–×1.6 and scaled to a distance drawn from ×0.5–×3 (log-uniform, per block);
- ``model``: the arm preset's own noisy reaches (sampled open loop from its belief) to goals 0.15–0.6 m away
  in random directions, one pace from ×0.6–×1.6 per person;
- ``people``: the eleven recorded arm people (TAT-HUM's and UE_ADL's, read and streamed as ``forecast_peers.py``
  reads them), each person's reaches in their recorded order, scored with the people model fitted on the other
  people only (leave one person out; ``--fits`` keeps the fits for the next run), with a table person by person and
  the targets: from a person's 6th reach on, the endpoint's and the +0.2 s forecast's 95 % regions hold 85–98 %; a
  new person's first reach 80–98 %.

Each person's reaches go through one :class:`~comanip.OnlineGoalEstimator` reset between reaches, which learns
from each finished one (``calibrated``), and through a fresh estimator per reach (``not calibrated``). Every
reach is followed by 0.15 s of the hand at rest on its endpoint, as a tracker sees it stop. Scored per reach
number: the endpoint estimate's error / D (median) and how often its 95 % region holds the endpoint at 25, 50,
75 and 90 % of MT, and the forecast's error / D and coverage at +0.2 s from 25 % and 50 % of MT.

    PYTHONPATH=src python -m benchmarks.person_calibration [--reaches 10] [--sources arm,model] [--markdown]
    PYTHONPATH=src python -m benchmarks.person_calibration --sources people [--fits /tmp/fits]

Outputs in ``--out`` (default benchmarks/results/person_calibration/): ``scores.csv`` (one row per reach, mode and
fraction), ``summary.md`` and ``coverage_by_reach.png``.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from forecast_peers import TATHUM, UE_ADL, people_models, people_reaches  # noqa: E402  (beside this script)
from forecast_scores import holds  # noqa: E402

FRACTIONS = (0.25, 0.5, 0.75, 0.9)
LEAD_S = 0.2
FORECASTS_FROM = (0.25, 0.5)
"""Fractions of MT from which the forecast at +LEAD_S is scored."""
FORECAST_SHOWN = 0.5
"""The one the tables of made people show."""
REST_S = 0.15
ARMS = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
MODES = ("calibrated", "not calibrated")


def transformed(recording, pace: float, scale: float):
    """The recording played ``pace`` times slower and ``scale`` times farther from its first position."""
    from comanip.recordings import Recording
    x0 = recording.position[0]
    return Recording(f"{recording.name} ×{pace:.2f} pace ×{scale:.2f} distance", recording.t * pace,
                     x0 + scale * (recording.position - x0), scale * recording.velocity / pace, recording.onset * pace,
                     recording.end_time * pace)


def arm_people(count: int, rng) -> list[list]:
    from comanip.recordings import load_tathum
    reaches = [trial.streamed_recording() for trial in load_tathum(ARMS)]
    people = []
    for first in range(0, len(reaches) - count + 1, count):
        pace, scale = np.exp(rng.uniform(np.log(0.6), np.log(1.6))), np.exp(rng.uniform(np.log(0.5), np.log(3.0)))
        people.append([transformed(r, pace, scale) for r in reaches[first:first + count]])
    return people


def model_people(count: int, people: int, rng) -> list[list]:
    import comanip
    from comanip.belief import sample_trajectories
    from comanip.recordings import recording_from_samples
    model = comanip.presets.arm()
    planner = comanip.Planner(model)
    out = []
    for p in range(people):
        pace = np.exp(rng.uniform(np.log(0.6), np.log(1.6)))
        person = []
        for k in range(count):
            direction = rng.normal(size=3)
            goal = rng.uniform(0.15, 0.6) * direction / np.linalg.norm(direction)
            plan = planner.solve(np.zeros(model.state_size), goal, model.width)
            states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
            rest = np.repeat(states[:1, :model.n], 10, axis=0)
            t = (np.r_[np.arange(-10, 0) * model.h, plan.t] + 10 * model.h) * pace
            person.append(recording_from_samples(f"model person {p} ×{pace:.2f}/{k}", t,
                                                 np.r_[rest, states[:, :model.n]], step=0.01 * pace))
        out.append(person)
    return out


def scored_reach(estimator, recording) -> dict:
    """Stream ``recording`` then REST_S at rest into ``estimator``; the scores (module docstring), with constant
    velocity's error at +LEAD_S s from the same samples beside the forecast's."""
    from comanip.estimation.forecast.path_baselines import constant_velocity
    D, end = recording.distance, recording.end
    until = {f: recording.seen_until(f) for f in FRACTIONS}
    scores = {}
    last = len(recording.t)
    step = recording.step
    rest_t = recording.t[-1] + step * np.arange(1, int(round(REST_S / step)) + 1)
    for k in range(last + len(rest_t)):
        if k < last:
            estimate = estimator.update(recording.t[k], recording.position[k], recording.velocity[k])
        else:
            estimator.update(rest_t[k - last], end, np.zeros_like(end))
            continue
        for f, seen in until.items():
            if seen == k + 1:
                e = estimate.goal - end
                scores[f"error {f:g}"] = float(np.linalg.norm(e)) / D
                scores[f"covered {f:g}"] = holds(e, estimate.goal_covariance)
                if f in FORECASTS_FROM and estimate.forecast is not None:
                    ahead = estimate.forecast.at([recording.t[k] + LEAD_S])
                    there = recording.position_at(recording.t[k] + LEAD_S)
                    e = ahead.position[0] - there
                    scores[f"forecast error {f:g}"] = float(np.linalg.norm(e)) / D
                    extrapolated = constant_velocity(recording.position[k], recording.velocity[k], [LEAD_S])[0]
                    scores[f"constant velocity error {f:g}"] = float(np.linalg.norm(extrapolated - there)) / D
                    scores[f"forecast covered {f:g}"] = holds(e, ahead.covariance[0])
    return scores


def run_people(people: dict[str, list], mode: str, say, people_models: dict | None = None) -> list[dict]:
    """Rows of :func:`scored_reach` for each person's reaches ({person: recordings}) in order, through one estimator
    reset between reaches (``calibrated``) or a fresh one per reach; ``people_models``: {person: the people model
    their estimator reads} (None: the preset's)."""
    import comanip
    from comanip.estimation import OnlineOptions
    model = comanip.presets.arm()
    rows = []
    for p, (person, reaches) in enumerate(people.items()):
        options = OnlineOptions() if people_models is None else OnlineOptions(people_model=people_models[person])
        estimator = None
        for number, recording in enumerate(reaches, start=1):
            start = np.r_[recording.position[0], np.zeros(model.state_size - model.n)]
            if estimator is None or mode == "not calibrated":
                estimator = comanip.OnlineGoalEstimator(model, start, options=options)
            else:
                estimator.reset(start)          # learns from the reach before
            rows.append({"person": person, "reach": number, "mode": mode, **scored_reach(estimator, recording)})
        say(f"  {mode}: person {p + 1}/{len(people)}")
    return rows


GROUPS = {"1st": (1, 1), "2nd": (2, 2), "3rd–5th": (3, 5), "6th on": (6, 10**6)}


def markdown(rows, source: str, people: int, count: int) -> str:
    lines = [f"`{source}`: {people} people of {count} reaches. Per reach of a person: endpoint error / D (median) at "
             f"{' / '.join(f'{100 * f:g}' for f in FRACTIONS)} % of MT, its 95 % region's coverage there, and the "
             f"forecast at +{LEAD_S:g} s from {100 * FORECAST_SHOWN:g} % of MT (error / D median; coverage), calibrated "
             "beside not calibrated.", "",
             "| reach | mode | endpoint error / D | endpoint coverage | forecast error / D | forecast coverage |",
             "|---|---|---|---|---|---|"]
    for group, (low, high) in GROUPS.items():
        for mode in MODES:
            chosen = [r for r in rows if r["mode"] == mode and low <= r["reach"] <= high]
            if not chosen:
                continue
            errors = " / ".join(f"{np.nanmedian([r.get(f'error {f:g}', np.nan) for r in chosen]):.3f}" for f in FRACTIONS)
            coverage = " / ".join(f"{100 * np.mean([r[f'covered {f:g}'] for r in chosen if f'covered {f:g}' in r]):.0f}"
                                  for f in FRACTIONS)
            forecast = [r for r in chosen if f"forecast error {FORECAST_SHOWN:g}" in r]
            lines.append(f"| {group} | {mode} | {errors} | {coverage} % | "
                         f"{np.median([r[f'forecast error {FORECAST_SHOWN:g}'] for r in forecast]):.3f} | "
                         f"{100 * np.mean([r[f'forecast covered {FORECAST_SHOWN:g}'] for r in forecast]):.0f} % |")
    return "\n".join(lines)


LATER = 6
"""A person's reaches from this one on are scored as a person the estimator knows."""
BAND, FIRST_BAND = (85, 98), (80, 98)
"""Where a 95 % region's coverage should lie (%): from a person's LATER-th reach on, and on a first reach."""


def people_markdown(rows) -> str:
    """Person by person: the endpoint's coverage (pooled over FRACTIONS) and the forecast's at +LEAD_S s (pooled over
    FORECASTS_FROM) on the first reach and from the LATER-th on, calibrated and not, with the median errors; then
    the targets."""
    people = list(dict.fromkeys(r["person"] for r in rows))
    lines = [f"Person by person, each with the people model fitted on the other people: the 95 % regions' coverage, "
             f"the endpoint's pooled over {' / '.join(f'{100 * f:g}' for f in FRACTIONS)} % of MT and the forecast's at "
             f"+{LEAD_S:g} s pooled over {' / '.join(f'{100 * f:g}' for f in FORECASTS_FROM)} % of MT, on the first "
             f"reach and from the {LATER}th reach on (calibrated; not calibrated), and from the {LATER}th reach on the "
             f"endpoint's median error / D at 50 % of MT and the forecast's at +{LEAD_S:g} s (pooled over "
             f"{' / '.join(f'{100 * f:g}' for f in FORECASTS_FROM)} % of MT; constant velocity's from the same samples)", "",
             "| person | reaches | endpoint, 1st reach | endpoint, later | forecast, later | error / D at 50 %, later | "
             f"forecast error / D, later: calibrated; not; constant velocity |",
             "|---|---|---|---|---|---|---|"]
    endpoint_keys = [f"covered {f:g}" for f in FRACTIONS]
    forecast_keys = [f"forecast covered {f:g}" for f in FORECASTS_FROM]

    def pooled(chosen, keys):
        values = [r[key] for r in chosen for key in keys if key in r]
        return 100 * float(np.mean(values)) if values else float("nan")

    def pooled_median(chosen, name):
        values = [r[f"{name} {f:g}"] for r in chosen for f in FORECASTS_FROM if f"{name} {f:g}" in r]
        return float(np.median(values)) if values else float("nan")

    later_shares, first = {}, []
    for person in people:
        mine = {mode: [r for r in rows if r["person"] == person and r["mode"] == mode] for mode in MODES}
        later = {mode: [r for r in mine[mode] if r["reach"] >= LATER] for mode in MODES}
        first += [r[key] for r in mine[MODES[0]] if r["reach"] == 1 for key in endpoint_keys if key in r]
        later_shares[person] = (pooled(later[MODES[0]], endpoint_keys), pooled(later[MODES[0]], forecast_keys))
        cells = [f"{pooled([r for r in mine[MODES[0]] if r['reach'] == 1], endpoint_keys):.0f} %",
                 "; ".join(f"{pooled(later[mode], endpoint_keys):.0f}" for mode in MODES) + " %",
                 "; ".join(f"{pooled(later[mode], forecast_keys):.0f}" for mode in MODES) + " %",
                 "; ".join(f"{np.nanmedian([r.get('error 0.5', np.nan) for r in later[mode]]):.3f}" for mode in MODES),
                 "; ".join(f"{pooled_median(later[mode], key):.3f}"
                           for mode, key in ((MODES[0], "forecast error"), (MODES[1], "forecast error"),
                                             (MODES[0], "constant velocity error")))]
        lines.append(f"| {person} | {len(mine[MODES[0]])} | " + " | ".join(cells) + " |")
    inside = lambda value, band: band[0] <= value <= band[1]
    first_share = 100 * float(np.mean(first))
    lines += ["", "| target (leave-one-person-out, calibrated) | measured | met |", "|---|---|---|"]
    for index, name in enumerate(("endpoint", f"+{LEAD_S:g} s forecast")):
        shares = [later_shares[person][index] for person in people]
        met = sum(inside(share, BAND) for share in shares)
        lines.append(f"| from a person's {LATER}th reach on, the {name}'s 95 % region holds {BAND[0]}–{BAND[1]} % "
                     f"(every person) | {min(shares):.0f}–{max(shares):.0f} %, {met} of {len(people)} people inside | "
                     f"{'yes' if met == len(people) else 'no'} |")
    lines.append(f"| a new person's first reach: the endpoint's 95 % region holds {FIRST_BAND[0]}–{FIRST_BAND[1]} % "
                 f"(pooled over people) | {first_share:.0f} % | {'yes' if inside(first_share, FIRST_BAND) else 'no'} |")
    return "\n".join(lines)


def figure(results: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator
    fig, axes = plt.subplots(1, len(results), figsize=(5 * len(results), 3.6), squeeze=False)
    for ax, (source, rows) in zip(axes[0], results.items()):
        people = {r["person"] for r in rows}
        count = max(n for n in range(1, max(r["reach"] for r in rows) + 1)     # reach numbers half the people reach
                    if 2 * len({r["person"] for r in rows if r["reach"] == n}) >= len(people))
        for mode, style in zip(MODES, ("-o", "--s")):
            coverage = [100 * np.mean([r["covered 0.5"] for r in rows if r["mode"] == mode and r["reach"] == n
                                       and "covered 0.5" in r]) for n in range(1, count + 1)]
            ax.plot(range(1, count + 1), coverage, style, label=mode)
        ax.axhspan(85, 98, color="0.9", label="85–98 %")
        ax.set(title=f"{source}: 95 % region at 50 % of MT", xlabel="reach of the person", ylabel="holds the endpoint (%)",
               ylim=(0, 102))
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reaches", type=int, default=10, help="reaches per person")
    parser.add_argument("--model-people", type=int, default=8, help="people of the model's own reaches")
    parser.add_argument("--sources", default="arm,model",
                        help="a comma-separated list of arm, model (people made from what the repository has) and people "
                             "(the recorded arm people, leave-one-person-out)")
    parser.add_argument("--fits", type=Path, default=None,
                        help="people: a folder to keep the leave-one-person-out people models in for the next run")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "person_calibration")
    parser.add_argument("--markdown", action="store_true", help="print only the tables on stdout (progress on stderr)")
    parser.add_argument("--figure", type=Path, default=None, help="also save the figure here (e.g. under docs/figures)")
    args = parser.parse_args(argv)
    log = sys.stderr if args.markdown else sys.stdout
    say = lambda line: print(line, file=log, flush=True)
    warnings.simplefilter("ignore")          # implausible-looking scaled reaches are meant
    rng = np.random.default_rng(args.seed)
    numbered = lambda people: {str(p): reaches for p, reaches in enumerate(people)}
    makers = {"arm": lambda: numbered(arm_people(args.reaches, rng)),
              "model": lambda: numbered(model_people(args.reaches, args.model_people, rng)),
              "people": lambda: people_reaches(TATHUM, UE_ADL)}
    sources = [s.strip() for s in args.sources.split(",") if s.strip()]
    if unknown := sorted(set(sources) - set(makers)):
        parser.error(f"--sources takes arm, model and people, got {', '.join(unknown)}")
    if "arm" in sources and not ARMS.is_dir():
        sys.exit(f"no arm reaches at {ARMS}")
    args.out.mkdir(parents=True, exist_ok=True)
    results, tables, began = {}, [], time.perf_counter()
    for source in sources:
        people = makers[source]()
        if source == "people" and len(people) < 2:
            sys.exit(f"leave-one-person-out needs at least two people; {TATHUM} and {UE_ADL} hold {len(people)}")
        say(f"{source}: {len(people)} people")
        models = people_models(people, args.fits, log) if source == "people" else None
        rows = [row for mode in MODES for row in run_people(people, mode, say, models)]
        results[source] = rows
        count = f"{min(map(len, people.values()))}–{max(map(len, people.values()))}" if source == "people" else args.reaches
        tables.append(markdown(rows, source, len(people), count))
        if source == "people":
            tables.append(people_markdown(rows))
    text = "\n\n".join(tables)
    print(text)
    say(f"{time.perf_counter() - began:.0f} s")
    with open(args.out / "scores.csv", "w", newline="") as stream:
        names = sorted({key for rows in results.values() for row in rows for key in row})
        writer = csv.DictWriter(stream, fieldnames=["source", *names])
        writer.writeheader()
        for source, rows in results.items():
            writer.writerows({"source": source, **row} for row in rows)
    (args.out / "summary.md").write_text(text + "\n")
    figure(results, args.out / "coverage_by_reach.png")
    if args.figure:
        figure(results, args.figure)
    say(f"wrote {args.out}")


if __name__ == "__main__":
    main()
