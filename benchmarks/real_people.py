"""Goal prediction on recorded people: where does a moving hand stop, predicted from its first part?

Every movement of a split of the ``cursory`` mouse recordings (``pip install -e ".[data]"``; the held-out
split only to report) is observed sample by sample (every 10 ms) from its first sample; at 10, 25, 50, 75 and
90 % of its movement time (MT, from the onset) each predictor's latest endpoint is scored by
error / D = |g_hat - end| / |end - start|. Printed: the median and interquartile range per fraction, how
often the predictor's 95 % region holds the endpoint (predictors with a covariance), how often it is worse
than the current position by more than 0.05 D, and the update time. ``--source simulated`` runs the same
table on reaches sampled from a reaching model's own noise (open loop, as the model's belief assumes);
``--source people`` on the eleven arm people (TAT-HUM's and UE_ADL's, streamed as ``forecast_peers.py`` streams them),
each person's reaches scored with the people model and the template library fitted on the other people's only, and
a table person by person with the targets over people (:func:`people_markdown`).

    python benchmarks/real_people.py                      # development split, every predictor
    python benchmarks/real_people.py --limit 200          # the first 200 movements of the split
    python benchmarks/real_people.py --split held_out     # the report split: run once per claimed improvement
    python benchmarks/real_people.py --source simulated   # the model's own reaches
    python benchmarks/real_people.py --source people      # leave-one-person-out over the arm people

Outputs in ``--out`` (default benchmarks/results/real_people_<source>_<split>/): ``errors.csv`` (one row per
movement, fraction and predictor), ``summary.json``, ``summary.md`` and ``error_by_fraction.png``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from comanip.estimation.people.endpoint_baselines import EndpointPrediction, PrefixPredictor

sys.path.insert(0, str(Path(__file__).resolve().parent))
from forecast_peers import leave_one_person_out as fits_without_each, people_models, people_reaches  # noqa: E402  (beside this script)
from forecast_scores import forecast_figure, forecast_markdown, forecast_rows, holds  # noqa: E402

FRACTIONS = (0.1, 0.25, 0.5, 0.75, 0.9)
ARMS = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches" / "tathum" / "data_3d"
UE_ADL = ARMS.parents[1] / "ue_adl"
WORSE_MARGIN = 0.05
FORECAST_EXAMPLES = 4
"""Movements whose forecasts the forecast figure shows (the first of the set)."""


def predictors(model_names, library_for, exclude_self: bool, people_for):
    """{name: factory(recording) -> online predictor with update(t, position, velocity)}; ``library_for(recording)``
    and ``people_for(recording)``: the template library and the people model that recording is scored with."""
    import comanip
    from comanip.estimation.people.endpoint_baselines import ConstantVelocity, CurrentPosition, MinimumJerkFit
    from comanip.estimation.people.template_matching import TemplateMatching

    made = {
        "current position": lambda r: CurrentPosition(r.position[0]),
        "constant velocity": lambda r: ConstantVelocity(r.position[0]),
        "minimum jerk": lambda r: MinimumJerkFit(r.position[0]),
        "template matching": lambda r: TemplateMatching(r.position[0], library_for(r), exclude=r.name if exclude_self else None),
        "people model": lambda r: _People(people_for(r), r.position[0]),
    }
    from comanip.estimation import OnlineOptions
    for name in model_names:
        model = comanip.presets.load(name)
        made[f"OnlineGoalEstimator ({name})"] = (lambda m: lambda r: _Online(comanip.OnlineGoalEstimator(
            m, np.r_[r.position[0], np.zeros(m.state_size - m.n)], options=OnlineOptions(people_model=people_for(r)))))(model)
    return made


class _People(PrefixPredictor):
    """The people endpoint model alone, fed the whole prefix at every update."""

    def __init__(self, model, start):
        super().__init__(start)
        self.model = model

    def predict(self, t, position, velocity):
        answer = self.model.predict(t, position, velocity, self.start)
        return EndpointPrediction(position[-1].copy()) if answer is None else answer


class _Online:
    """OnlineGoalEstimator behind the predictors' interface (goal and covariance of its estimate), keeping
    each update's time and estimate for :func:`diagnostics` (read after the movement, outside the timed update)."""

    def __init__(self, estimator):
        self.estimator = estimator
        self.trace: list = []

    def update(self, t, position, velocity):
        estimate = self.estimator.update(t, position, velocity)
        self.trace.append((float(t), estimate))
        return EndpointPrediction(estimate.goal, estimate.goal_covariance)


def diagnostics(trace, recording) -> dict:
    """From an online estimator's updates on one movement: the share of updates after a quarter of the
    movement that the reaching model carries (status not ``people_model``), the share whose goal (smoothed, and
    the explanation's unsmoothed one) moved by more than 0.1 D, the error / D of the smoothed minus the
    unsmoothed goal at half of the movement, and the forecast's stop minus the hand's (its end), over MT, then."""
    t = np.array([time_s for time_s, _ in trace])
    after = t >= recording.onset + 0.25 * recording.movement_time
    D = recording.distance
    half = trace[min(int(np.searchsorted(t, recording.onset + 0.5 * recording.movement_time, side="right")), len(t)) - 1][1]
    arrival = half.forecast.stop_time if half.forecast is not None else math.nan
    carried = [str(estimate.status) != "people_model" for (_, estimate), a in zip(trace, after) if a]
    out = {"model_share": float(np.mean(carried)) if carried else math.nan,
           "arrival": (arrival - recording.end_time) / recording.movement_time,
           "smoothing_cost": (float(np.linalg.norm(half.goal - recording.end))
                              - float(np.linalg.norm(half.unsmoothed_goal - recording.end))) / D}
    for key, field in (("jumps", "goal"), ("unsmoothed_jumps", "unsmoothed_goal")):
        goals = np.array([getattr(estimate, field) for _, estimate in trace])
        moved = np.linalg.norm(np.diff(goals, axis=0), axis=1) / D
        out[key] = float(np.mean(moved[after[1:]] > 0.1)) if after[1:].any() else math.nan
    return out


def run_predictor(factory, recording):
    """[(goal, covariance or None)] at FRACTIONS, the update times (s) and the predictor."""
    predictor = factory(recording)
    until = [recording.seen_until(f) for f in FRACTIONS]
    results, times, latest = [], [], None
    for k in range(max(until)):
        begin = time.perf_counter()
        answer = predictor.update(float(recording.t[k]), recording.position[k], recording.velocity[k])
        times.append(time.perf_counter() - begin)
        latest = answer.goal, answer.covariance
        while len(results) < len(until) and until[len(results)] == k + 1:
            results.append(latest)
    while len(results) < len(until):
        results.append(latest)
    return results, times, predictor


def simulated_recordings(model_name: str, count: int, seed: int):
    """Reaches sampled from a preset's own noise (open loop) to random goals, as recordings."""
    import comanip
    from comanip.belief import sample_trajectories
    from comanip.recordings import recording_from_samples

    model = comanip.presets.load(model_name)
    planner = comanip.Planner(model)
    rng = np.random.default_rng(seed)
    recordings = []
    for k in range(count):
        D, angle = rng.uniform(0.1, 0.6), rng.uniform(0, 2 * np.pi)
        goal = D * np.array([np.cos(angle), np.sin(angle)])
        start = np.zeros(model.state_size)
        plan = planner.solve(start, goal, model.width)
        states = sample_trajectories(model.body, model.h, model.kappa, plan.start, plan.torque, 1, rng, model.noise)[0]
        rest = np.repeat(states[:1, :model.n], 10, axis=0)            # 0.1 s at rest before the reach
        t = np.r_[np.arange(-10, 0) * model.h, plan.t] + 10 * model.h
        recordings.append(recording_from_samples(f"{model_name}/{k}", t, np.r_[rest, states[:, :model.n]], step=0.01,
                                                 target=goal))
    return recordings


def leave_one_person_out(tathum: Path, ue_adl: Path, limit: int | None, log, fits: Path | None = None):
    """The eleven arm people's reaches (``forecast_peers.people_reaches``) as one list of movements, the person of
    each (by name), and for each movement the people model and the template library fitted on the other people's
    reaches only (``forecast_peers.leave_one_person_out``: fitted once per person; the people models kept in
    ``fits``, a folder, where given: ``forecast_peers.people_models``)."""
    from comanip.estimation.people.template_matching import TemplateLibrary

    people = people_reaches(tathum, ue_adl, limit)
    if len(people) < 2:
        sys.exit(f"leave-one-person-out needs at least two people; {tathum} and {ue_adl} hold {len(people)}")
    person_of = {r.name: person for person, recordings in people.items() for r in recordings}
    if len(person_of) != sum(map(len, people.values())):
        sys.exit("two reaches share a name: the people's reaches must be told apart by name")

    models = people_models(people, fits, log)
    libraries = dict(fits_without_each(people, lambda rest: TemplateLibrary(rest, step=0.01)))
    movements = [r for recordings in people.values() for r in recordings]
    return movements, person_of, lambda r: models[person_of[r.name]], lambda r: libraries[person_of[r.name]]

def summarise(rows, names):
    """{predictor: {fraction: {median, q25, q75, coverage, worse}}} from the per-movement rows."""
    summary = {}
    by = {(r["predictor"], r["fraction"]): [] for r in rows}
    for r in rows:
        by[(r["predictor"], r["fraction"])].append(r)
    for name in names:
        summary[name] = {}
        for f in FRACTIONS:
            chosen = by.get((name, f), [])
            errors = np.array([r["error"] for r in chosen])
            covered = [r["covered"] for r in chosen if r["covered"] is not None]
            worse = np.mean([r["error"] > r["current_error"] + WORSE_MARGIN for r in chosen])
            summary[name][f] = {"median": float(np.median(errors)), "q25": float(np.percentile(errors, 25)),
                                "q75": float(np.percentile(errors, 75)), "worse_than_current": float(worse),
                                "coverage": float(np.mean(covered)) if covered else None}
    return summary


def markdown(summary, latency, count, title):
    lines = [f"{title} ({count} movements): error / D, median [IQR]; 95 % coverage; share worse than the current "
             f"position by > {WORSE_MARGIN} D; update time", "",
             "| predictor | " + " | ".join(f"{int(f * 100)} % of MT" for f in FRACTIONS) + " | update median / p95; first (ms) |",
             "|---|" + "---|" * (len(FRACTIONS) + 1)]
    for name, by_fraction in summary.items():
        cells = []
        for f in FRACTIONS:
            s = by_fraction[f]
            cell = f"{s['median']:.3f} [{s['q25']:.2f}–{s['q75']:.2f}]"
            if s["coverage"] is not None:
                cell += f"; cov {100 * s['coverage']:.0f} %"
            cell += f"; worse {100 * s['worse_than_current']:.0f} %"
            cells.append(cell)
        lat = latency[name]
        lines.append(f"| {name} | " + " | ".join(cells)
                     + f" | {1e3 * lat['median']:.2f} / {1e3 * lat['p95']:.2f}; {1e3 * lat['first_median']:.2f} |")
    return "\n".join(lines)


def diagnostics_markdown(diagnosed) -> str:
    """The online estimators' diagnostics (:func:`diagnostics`) as a markdown table."""
    lines = ["| online estimator | updates after 25 % of MT carried by the reaching model | updates after 25 % of MT "
             "moving the goal > 0.1 D (unsmoothed) | smoothed − unsmoothed error / D at 50 % of MT: median [p90] "
             "| predicted arrival − hand's at 50 % of MT, / MT: median |·| [p90] |", "|---|---|---|---|---|"]
    for name, rows in diagnosed.items():
        share = np.nanmean([r["model_share"] for r in rows])
        jumps, unsmoothed = (np.nanmean([r[key] for r in rows]) for key in ("jumps", "unsmoothed_jumps"))
        cost = [r["smoothing_cost"] for r in rows]
        arrival = np.abs([r["arrival"] for r in rows])
        lines.append(f"| {name} | {100 * share:.0f} % | {100 * jumps:.1f} % ({100 * unsmoothed:.1f} %) | "
                     f"{np.nanmedian(cost):+.3f} [{np.nanpercentile(cost, 90):+.3f}] | {np.nanmedian(arrival):.2f} "
                     f"[{np.nanpercentile(arrival, 90):.2f}] |")
    return "\n".join(lines)


AIMS = {0.25: 0.40, 0.5: 0.15, 0.75: 0.05, 0.9: 0.02}
"""The online estimator's aimed median error / D on arm reaches, by fraction of MT."""


def aims_markdown(name, summary, latency, diagnosed) -> str:
    """The online estimator ``name`` against the aims set for arm reaches, as a markdown table."""
    mine = summary[name]
    others = [other for other in summary if other != name]
    beaten = {f: [o for o in others if summary[o][f]["median"] <= mine[f]["median"]] for f in AIMS}
    rows = diagnosed[name]
    share = np.nanmean([r["model_share"] for r in rows])
    jumps = np.nanmean([r["jumps"] for r in rows])
    cost = float(np.nanmedian([r["smoothing_cost"] for r in rows]))
    arrival = float(np.nanmedian(np.abs([r["arrival"] for r in rows])))
    coverage = [mine[f]["coverage"] for f in AIMS]
    worse = max(mine[f]["worse_than_current"] for f in AIMS)
    yes = lambda ok: "yes" if ok else "no"
    errors = " / ".join(f"{mine[f]['median']:.3f}" for f in AIMS)
    lines = [f"`{name}` against its aims on these reaches:", "", "| aim | measured | met |", "|---|---|---|",
             "| below every other predictor at 25 / 50 / 75 / 90 % of MT | as good or better: "
             + "; ".join(f"{int(100 * f)} %: {', '.join(b) or 'none'}" for f, b in beaten.items())
             + f" | {yes(not any(beaten.values()))} |",
             f"| ≤ {' / '.join(f'{a:g}' for a in AIMS.values())} D | {errors} D | "
             f"{yes(all(mine[f]['median'] <= a for f, a in AIMS.items()))} |",
             f"| worse than the current position by > {WORSE_MARGIN} D in ≤ 5 % of (reach, fraction) pairs | at most "
             f"{100 * worse:.0f} % at a fraction | {yes(worse <= 0.05)} |",
             f"| 95 % region holds the endpoint in 85–98 % | {' / '.join(f'{100 * c:.0f}' for c in coverage)} % | "
             f"{yes(all(0.85 <= c <= 0.98 for c in coverage))} |",
             f"| after 25 % of MT, ≤ 1 % of updates move the goal by > 0.1 D | {100 * jumps:.1f} % | {yes(jumps <= 0.01)} |",
             f"| smoothing the goal costs ≤ 0.01 D at 50 % of MT (median over movements) | {cost:+.3f} D | {yes(cost <= 0.01)} |",
             f"| predicted arrival within 0.10 MT of the hand's at 50 % of MT | {arrival:.2f} MT (median) | {yes(arrival <= 0.1)} |",
             f"| the reaching model carries ≥ half of the updates after 25 % of MT | {100 * share:.0f} % | {yes(share >= 0.5)} |",
             f"| update median ≤ 2 ms, p95 ≤ 4 ms | {1e3 * latency[name]['median']:.1f} / {1e3 * latency[name]['p95']:.1f} ms | "
             f"{yes(latency[name]['median'] <= 2e-3 and latency[name]['p95'] <= 4e-3)} |"]
    return "\n".join(lines)


BASELINES = ("current position", "constant velocity", "minimum jerk", "template matching")
"""The simple rules an online estimator is judged against, person by person (the people model alone is a part of it)."""
PEOPLE_FRACTIONS = (0.25, 0.5, 0.75, 0.9)


def people_markdown(name: str, rows, diagnosed) -> str:
    """Person by person: the online estimator ``name``'s median error / D against the best of the simple rules at
    each fraction, its 95 % coverage (a new person's first reach: the estimator learns nothing across reaches here)
    and its goal jumps, then the targets over people."""
    people = list(dict.fromkeys(r["person"] for r in rows))
    rules = [rule for rule in BASELINES if any(r["predictor"] == rule for r in rows)]

    def median(predictor, person, f):
        errors = [r["error"] for r in rows if r["predictor"] == predictor and r["fraction"] == f
                  and person in (None, r["person"])]
        return float(np.median(errors)) if errors else math.nan

    def held(person, f):
        return [r["covered"] for r in rows if r["predictor"] == name and r["fraction"] == f and r["covered"] is not None
                and person in (None, r["person"])]

    def coverage(person, f):
        return float(np.mean(held(person, f))) if held(person, f) else math.nan

    def consistent(person, f):
        """Whether the count of reaches held at ``f`` is consistent with a region that holds 95 % of the time
        (two-sided binomial test at 5 %)."""
        from scipy.stats import binomtest
        each = held(person, f)
        return bool(each) and binomtest(int(sum(each)), len(each), 0.95).pvalue >= 0.05

    lines = [f"`{name}` person by person, each scored with the people model and templates of the other people only: "
             "median error / D at 25 / 50 / 75 / 90 % of MT, the best simple rule's (its name at 50 %), the 95 % region's "
             "coverage of a new person's first reach, and the share of updates after 25 % of MT that move the goal by "
             "> 0.1 D", "",
             "| person | reaches | estimator | best rule | best rule at 50 % | below every rule at 50 % | coverage | goal jumps |",
             "|---|---|---|---|---|---|---|---|"]
    below_at_half, jumps_by_person, covered_by_person = [], {}, {}
    for person in [*people, None]:
        mine = [median(name, person, f) for f in PEOPLE_FRACTIONS]
        best = [min(median(rule, person, f) for rule in rules) for f in PEOPLE_FRACTIONS]
        best_rule = min(rules, key=lambda rule: median(rule, person, 0.5))
        below = mine[1] < best[1]
        jumps = float(np.nanmean([d["jumps"] for d in diagnosed if person in (None, d["person"])]))
        covered = [coverage(person, f) for f in PEOPLE_FRACTIONS]
        if person is not None:
            below_at_half.append(below)
            jumps_by_person[person], covered_by_person[person] = jumps, covered
        count = sum(1 for r in rows if r["predictor"] == name and r["fraction"] == 0.5 and person in (None, r["person"]))
        lines.append(f"| {person or '**all reaches**'} | {count} | {' / '.join(f'{e:.3f}' for e in mine)} | "
                     f"{' / '.join(f'{e:.3f}' for e in best)} | {best_rule} | {'yes' if below else 'no'} | "
                     f"{' / '.join(f'{100 * c:.0f}' for c in covered)} % | {100 * jumps:.1f} % |")
    over_people = {f: float(np.median([median(name, person, f) for person in people])) for f in PEOPLE_FRACTIONS}
    rule_over_people = {f: min(float(np.median([median(rule, person, f) for person in people])) for rule in rules)
                        for f in PEOPLE_FRACTIONS}
    yes = lambda ok: "yes" if ok else "no"
    low = min(min(c) for c in covered_by_person.values())
    high = max(max(c) for c in covered_by_person.values())
    worst_jumps = max(jumps_by_person, key=jumps_by_person.get)
    lines += ["", "| target (leave-one-person-out) | measured | met |", "|---|---|---|",
              "| endpoint below every simple rule at 25–90 % of MT (median over people) | "
              + "; ".join(f"{int(100 * f)} %: {over_people[f]:.3f} vs {rule_over_people[f]:.3f}" for f in PEOPLE_FRACTIONS)
              + f" D | {yes(all(over_people[f] < rule_over_people[f] for f in PEOPLE_FRACTIONS))} |",
              f"| below every simple rule at 50 % of MT for ≥ 80 % of people | {sum(below_at_half)} of {len(people)} | "
              f"{yes(sum(below_at_half) >= 0.8 * len(people))} |",
              f"| a new person's first reach: the 95 % region holds the endpoint in 80–98 % (every person, 25–90 % of MT) | "
              f"{100 * low:.0f}–{100 * high:.0f} % | {yes(0.8 <= low and high <= 0.98)} |",
              f"| the same judged by a binomial test: person-fractions whose count held is consistent with 95 % (two-sided, "
              f"5 %) | {sum(consistent(p, f) for p in people for f in PEOPLE_FRACTIONS)} of "
              f"{len(people) * len(PEOPLE_FRACTIONS)} | "
              f"{yes(all(consistent(p, f) for p in people for f in PEOPLE_FRACTIONS))} |",
              f"| after 25 % of MT, ≤ 1 % of updates move the goal by > 0.1 D (every person) | at most "
              f"{100 * jumps_by_person[worst_jumps]:.1f} % ({worst_jumps}) | {yes(jumps_by_person[worst_jumps] <= 0.01)} |"]
    return "\n".join(lines)


PUBLISHED_PX = {0.5: 83, 0.75: 48, 0.9: 39}
"""Kinematic template matching's published errors on mouse movements of 100–800 px (Pasqual & Wobbrock 2014), px."""


def published_comparison(rows, scale: float) -> str:
    """A line comparing template matching's median endpoint error in pixels, on the movements of 100–800 px,
    with the published one."""
    ours = []
    for f, published in PUBLISHED_PX.items():
        errors = [r["error"] * r["distance_m"] / scale for r in rows if r["predictor"] == "template matching"
                  and r["fraction"] == f and 100 <= r["distance_m"] / scale <= 800]
        ours.append(f"{np.median(errors):.0f} px at {int(100 * f)} % (published {published} px)")
    return ("Template matching here, median endpoint error on the movements of 100–800 px: " + ", ".join(ours)
            + "; published: Pasqual & Wobbrock 2014, their own mouse recordings.")


def figure(summary, path: Path, title: str):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4))
    x = np.array(FRACTIONS)
    for name, by_fraction in summary.items():
        med = np.array([by_fraction[f]["median"] for f in FRACTIONS])
        lo = np.array([by_fraction[f]["q25"] for f in FRACTIONS])
        hi = np.array([by_fraction[f]["q75"] for f in FRACTIONS])
        line, = ax.plot(x, med, marker="o", label=name)
        ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.12)
    ax.set_yscale("log")
    ax.set_xlabel("fraction of the movement time seen")
    ax.set_ylabel("endpoint error / D (median, IQR)")
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--source", choices=("cursory", "arms", "people", "simulated"), default="cursory",
                        help="cursory: mouse movements; arms: motion-capture arm reaches (--arms); people: the eleven arm "
                             "people (--arms, --ue-adl), each scored leave-one-person-out; simulated: the model's own")
    parser.add_argument("--arms", type=Path, default=ARMS, help="a TAT-HUM 3-D data folder (trajectory_data/, trial_data/)")
    parser.add_argument("--ue-adl", type=Path, default=UE_ADL, help="a folder of people's Vicon Nexus exports (--source people)")
    parser.add_argument("--fits", type=Path, default=None,
                        help="--source people: a folder to keep the leave-one-person-out people models in for the next run")
    parser.add_argument("--split", choices=("development", "held_out"), default="development",
                        help="cursory split; held_out only to report a claimed improvement")
    parser.add_argument("--limit", type=int, default=None, help="at most this many movements")
    parser.add_argument("--models", default=None, help="presets whose OnlineGoalEstimator is scored "
                        "(default: planar,human,people; arms: arm,human_cartesian)")
    parser.add_argument("--only", default=None, help="comma-separated predictor names to run (default: all)")
    parser.add_argument("--scale", type=float, default=None, help="cursory pixels to metres (m/px)")
    parser.add_argument("--count", type=int, default=100, help="simulated reaches")
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--markdown", action="store_true", help="print only the table on stdout (progress on stderr)")
    parser.add_argument("--figure", type=Path, default=None, help="also save the figure here (e.g. under docs/figures)")
    args = parser.parse_args(argv)
    log = sys.stderr if args.markdown else sys.stdout
    from comanip.estimation.people.template_matching import TemplateLibrary
    from comanip.estimation.people.people_model import PeopleModel, shipped_people_model
    from comanip.recordings import load_cursory, load_tathum
    from comanip.recordings.cursory_data import SCALE

    scale = args.scale or SCALE
    models = args.models or {"arms": "arm,human_cartesian", "people": "arm"}.get(args.source, "planar,human,people")
    kind = "arm" if args.source in ("arms", "people") else "mouse"
    person_of = {}
    if args.source == "people":
        if args.split != "development":
            sys.exit("the arm people's held-out people are not in these folders: they are scored elsewhere")
        movements, person_of, people_for, library_for = leave_one_person_out(args.arms, args.ue_adl, args.limit, log, args.fits)
        title = (f"{len(set(person_of.values()))} arm people (TAT-HUM's, UE_ADL's), development split, streamed as a "
                 "tracker delivers them, each scored with the people model and templates of the other people only")
    elif args.source == "arms":
        if args.split != "development":
            sys.exit("the arm reaches' held-out split is not in this folder: it is scored elsewhere")
        trials = load_tathum(args.arms)
        if args.limit:
            trials = trials[:args.limit]
        development = [trial.streamed_recording() for trial in trials]      # as a live tracker delivers them
        movements = development
        title = f"motion-capture arm reaches ({args.arms.name}), development split, streamed at 125 Hz"
    else:
        development = load_cursory("development", scale=scale)
        if args.source == "cursory":
            recordings = development if args.split == "development" else load_cursory("held_out", scale=scale)
            title = f"cursory mouse movements, {args.split} split"
        else:
            recordings = simulated_recordings("planar", args.count, seed=1)
            title = "reaches sampled from the planar preset's own noise"
        if args.limit:
            recordings = recordings[:args.limit]
        movements = recordings
    if args.source != "people":
        library = TemplateLibrary(development, step=0.01)
        library_for = lambda r: library
        if args.source != "simulated" and args.split == "development":
            # the shipped people models were fitted on this split: score each movement with one fitted on the other half
            print(f"fitting the {kind} people model on each half of the development split ...", flush=True, file=log)
            folds = [PeopleModel.fit(development[1 - k::2], kind=kind) for k in (0, 1)]
            half = {r.name: k % 2 for k, r in enumerate(development)}
            people_for = lambda r: folds[half[r.name]]
        else:
            people_for = lambda r: shipped_people_model(kind)
    made = predictors([m for m in models.split(",") if m], library_for, exclude_self=args.split == "development",
                      people_for=people_for)
    if args.only:
        made = {k: v for k, v in made.items() if any(o.strip() in k for o in args.only.split(","))}
    names = list(made)
    out = args.out or Path(__file__).parent / "results" / f"real_people_{args.source}_{args.split if args.source != 'simulated' else 'planar'}"
    out.mkdir(parents=True, exist_ok=True)
    rows, latency, diagnosed, forecasts, examples = [], {name: [] for name in names}, {}, {}, {}
    first = {name: [] for name in names}
    begin = time.perf_counter()
    for i, recording in enumerate(movements):
        D = recording.distance
        current = None
        for name in names:
            answers, times, predictor = run_predictor(made[name], recording)
            if isinstance(predictor, _Online):
                diagnosed.setdefault(name, []).append(diagnostics(predictor.trace, recording)
                                                      | {"person": person_of.get(recording.name, "")})
                forecasts.setdefault(name, []).extend(forecast_rows(predictor.trace, recording, name, predictor.estimator))
                if len(examples.setdefault(name, [])) < FORECAST_EXAMPLES:
                    examples[name].append((recording, predictor.trace))
            latency[name] += times[1:]
            first[name].append(times[0])
            errors = [float(np.linalg.norm(goal - recording.end)) / D for goal, _ in answers]
            if name == "current position":
                current = errors
            for f, (goal, cov), error in zip(FRACTIONS, answers, errors):
                covered = None if cov is None else holds(goal - recording.end, cov)
                rows.append({"person": person_of.get(recording.name, ""), "movement": recording.name, "predictor": name, "fraction": f, "distance_m": D,
                             "movement_time_s": recording.movement_time, "error": error, "covered": covered})
        for row in rows[-len(names) * len(FRACTIONS):]:
            row["current_error"] = current[FRACTIONS.index(row["fraction"])] if current else math.nan
        if (i + 1) % 50 == 0 or i + 1 == len(movements):
            print(f"  {i + 1}/{len(movements)} movements, {time.perf_counter() - begin:.0f} s", flush=True, file=log)
    summary = summarise(rows, names)
    lat = {name: {"median": float(np.median(v)) if v else math.nan, "p95": float(np.percentile(v, 95)) if v else math.nan,
                  "first_median": float(np.median(first[name]))} for name, v in latency.items()}
    table = markdown(summary, lat, len(movements), title)
    if diagnosed:
        table += "\n\n" + diagnostics_markdown(diagnosed)
    for name, scored in forecasts.items():
        table += "\n\n" + forecast_markdown(scored, name)
    if args.source == "people":
        for name in diagnosed:
            table += "\n\n" + people_markdown(name, rows, diagnosed[name])
    if args.source == "arms":
        for name in diagnosed:
            table += "\n\n" + aims_markdown(name, summary, lat, diagnosed)
    if args.source == "cursory" and "template matching" in names:
        table += "\n\n" + published_comparison(rows, scale)
    print(table)
    import csv
    with open(out / "errors.csv", "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    if forecasts:
        with open(out / "forecasts.csv", "w", newline="") as stream:
            writer = csv.DictWriter(stream, fieldnames=list(next(iter(forecasts.values()))[0]))
            writer.writeheader()
            for scored in forecasts.values():
                writer.writerows(scored)
    (out / "summary.json").write_text(json.dumps({"source": args.source, "split": args.split, "scale_m_per_px": scale,
                                                  "movements": len(movements), "summary": summary, "latency_s": lat},
                                                 indent=1))
    (out / "summary.md").write_text(table + "\n")
    figure(summary, out / "error_by_fraction.png", title)
    if args.figure:
        figure(summary, args.figure, title)
    for name, shown in examples.items():
        for where in [out / "forecast_paths.png"] + ([args.figure.with_name(args.figure.stem + "_forecast.png")] if args.figure else []):
            forecast_figure(shown, where, f"{name}: the forecast of the hand on {title}")
    print(f"wrote {out}", file=log)


if __name__ == "__main__":
    main()
