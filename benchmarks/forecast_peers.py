"""Where will the hand be 0.1, 0.2 and 0.3 s from now? A forecaster learned from other people, beside the kinematic
forecasters and comanip's forecast, leave-one-person-out over the recorded arm people.

**People.** TAT-HUM's participant (``--tathum``, a TAT-HUM 3-D folder) and the UE_ADL people (``--ue-adl``, a folder
of Vicon Nexus exports, one sub-folder per person, the fingertip of the arm that reached), each reach streamed as a
live tracker delivers it (``TrackedSamples.streamed_recording``: from 0.15 s before its onset, at 125 Hz or the
tracker's rate when slower, positions as recorded, backward-difference velocities over 24 ms); a reach whose hand
moves within 0.15 s of the recording's start is left out.

**Leave one person out.** For each person, the learned forecaster (and, with ``--comanip``, the people model of
comanip's online estimator) is fitted on the reaches of every other person only, and scored on that person's.

**The learned forecaster** (:class:`LearnedForecaster`) is causal and reads only the hand's recent kinematics: at a
sample, its positions over the last 0.2 s (every 25 ms) relative to the current one, and its velocities there. It
is normalised so it transfers across distances and labs: every length is divided by the peak speed so far (lengths
become times, s; velocities fractions of the peak), since reaches of different amplitudes but like durations differ
mostly by that scale; and every vector is turned into the frame of the motion (first axis along the current velocity
plus the mean velocity of the window, second along the window's bend, third normal to both), since the labs' axes
differ. It predicts the offset from the current position at each lead in that frame, one gradient-boosted tree
ensemble (scikit-learn's HistGradientBoostingRegressor) per lead and axis, trained on every sample of every training
reach from its onset to its end.

**Scores** (``forecast_scores.py``): from the sample at 25 % and 50 % of a reach's movement time, each forecaster's
position at +0.1/+0.2/+0.3 s against the recorded hand's (held at its endpoint after the end), error / D; the
hand staying, constant velocity and constant acceleration from the same sample; with ``--comanip`` the forecast of
``OnlineGoalEstimator`` (``arm`` preset, the people model fitted on the other people) fed every sample from the
stream's start.

    python benchmarks/forecast_peers.py                       # every person, the kinematic and the learned forecasters
    python benchmarks/forecast_peers.py --comanip --markdown  # and comanip's forecast; print only the tables

Outputs in ``--out`` (default benchmarks/results/forecast_peers/): ``errors.csv`` (one row per person, reach, start
fraction, lead and forecaster), ``summary.json`` (medians per person), ``summary.md`` (the tables).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from forecast_scores import FROM, LEADS, kinematic_paths, truth  # noqa: E402  (beside this script)

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "arm_reaches"
TATHUM = DATA / "tathum" / "data_3d"
UE_ADL = DATA / "ue_adl"
LAGS_S = np.arange(0.0, 0.2 + 1e-9, 0.025)
"""How far back (s) the learned forecaster reads the hand: now and every 25 ms to 0.2 s."""
SPEED_FLOOR = 0.05
"""Peak speed (m/s) below which lengths are scaled by this instead (a hand that has hardly moved)."""
KINEMATIC = ("hand stays", "constant velocity", "constant acceleration")
LEARNED = "learned (trees on the last 0.2 s)"
COMANIP = "OnlineGoalEstimator (arm)"


def people_trials(tathum: Path | None, ue_adl: Path | None, limit: int | None = None) -> dict[str, list]:
    """{person: trials (:class:`~comanip.recordings.TrackedSamples`)} of TAT-HUM's and UE_ADL's people (a folder None
    or missing: none of its people), the reaches whose hand rests for the stream's lead before their onset;
    ``limit``: at most that many reaches per person."""
    from comanip.recordings import load_nexus_trajectories, load_tathum
    from comanip.recordings.motion_capture import STREAM_LEAD_S

    trials = []
    if tathum is not None and tathum.is_dir():
        trials += [(f"TAT-HUM {t.label['participant']}", t) for t in load_tathum(tathum)]
    if ue_adl is not None and ue_adl.is_dir():
        trials += [(t.label["participant"], t) for t in load_nexus_trajectories(ue_adl)]
    people: dict[str, list] = {}
    for person, trial in trials:
        if trial.recording().onset >= STREAM_LEAD_S and (limit is None or len(people.get(person, [])) < limit):
            people.setdefault(person, []).append(trial)
    return people


def people_reaches(tathum: Path | None, ue_adl: Path | None, limit: int | None = None) -> dict[str, list]:
    """{person: streamed recordings (:class:`~comanip.recordings.Recording`)} of :func:`people_trials`."""
    return {person: [trial.streamed_recording() for trial in trials]
            for person, trials in people_trials(tathum, ue_adl, limit).items()}


def add_people_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """``--tathum`` and ``--ue-adl``, the folders the arm people are read from, on ``parser``."""
    parser.add_argument("--tathum", type=Path, default=TATHUM, help="a TAT-HUM 3-D data folder (default: %(default)s)")
    parser.add_argument("--ue-adl", type=Path, default=UE_ADL, help="a folder of people's Nexus exports (default: %(default)s)")
    return parser


def people_of(args, parser: argparse.ArgumentParser, limit: int | None = None) -> dict[str, list]:
    """:func:`people_reaches` of the folders ``args`` name (:func:`add_people_arguments`); the parser's one-line error
    when they hold fewer than two people (leave-one-person-out needs two)."""
    people = people_reaches(args.tathum, args.ue_adl, limit)
    if len(people) < 2:
        parser.error(f"leave-one-person-out needs at least two people; {args.tathum} and {args.ue_adl} hold {len(people)}")
    return people


def people_from_command_line(description: str, argv=None) -> dict[str, list]:
    """:func:`people_of` the folders a command line of :func:`add_people_arguments` alone names."""
    parser = add_people_arguments(argparse.ArgumentParser(description=description))
    return people_of(parser.parse_args(argv), parser)


def _at(t: np.ndarray, values: np.ndarray, times: np.ndarray) -> np.ndarray:
    """``values`` (K, d) interpolated linearly at ``times`` (M,) within t (K,), held at the ends: (M, d)."""
    return np.column_stack([np.interp(times, t, column) for column in values.T])


def motion_frame(velocity: np.ndarray, chord: np.ndarray) -> np.ndarray:
    """Rows (d, d): the unit vector along ``velocity`` (d,), then along the part of ``chord`` (d,) normal to it, then
    (3-D) their cross product; axes of the world where the two give no direction."""
    d = len(velocity)
    q, r = np.linalg.qr(np.column_stack([velocity, chord, np.eye(d)]))
    q = q[:, :d] * np.where(np.diag(r)[:d] < 0, -1.0, 1.0)     # the first axes point along velocity and chord
    if d == 3:
        q[:, 2] = np.cross(q[:, 0], q[:, 1])
    return q.T


def window_features(t: np.ndarray, position: np.ndarray, velocity: np.ndarray, k: int):
    """What the learned forecaster reads at sample k, causally (samples 0 … k only): (features (F,), the frame's
    rows (d, d), the length scale s = max(peak speed so far, SPEED_FLOOR) m/s). The features are rounded to 1e-9 (they
    are in units of the length scale), so that round-off, such as a planar reach's out-of-plane part, never splits a
    tree: a reach turned, moved or scaled reads the same features."""
    now = t[k]
    seen_t, seen_x, seen_v = t[:k + 1], position[:k + 1], velocity[:k + 1]
    back = now - LAGS_S
    x, v = _at(seen_t, seen_x, back), _at(seen_t, seen_v, back)
    scale = max(float(np.linalg.norm(seen_v, axis=1).max()), SPEED_FLOOR)
    frame = motion_frame(v[0] + (x[0] - x[-1]) / LAGS_S[-1], x[len(x) // 2] - 0.5 * (x[0] + x[-1]))
    features = np.r_[((x[1:] - x[0]) @ frame.T).ravel(), (v @ frame.T).ravel()] / scale
    return np.round(features, 9), frame, scale


class LearnedForecaster:
    """Gradient-boosted trees on the hand's last 0.2 s (module docstring): ``fit`` on recordings, then ``predict``
    where the hand will be at +LEADS s from a sample of a recording."""

    def __init__(self, seed: int = 0, max_iter: int = 200, every: int = 1):
        self.seed, self.max_iter, self.every = seed, max_iter, every
        self.trained_on: tuple[str, ...] = ()
        """Names of the recordings the forecaster was fitted on."""
        self.models: list = []

    def fit(self, recordings) -> "LearnedForecaster":
        """Fit on every ``every``-th sample from each recording's onset to its end."""
        from sklearn.ensemble import HistGradientBoostingRegressor
        from threadpoolctl import ThreadpoolController

        X, Y = [], []
        for recording in recordings:
            for k in np.flatnonzero((recording.t >= recording.onset - 1e-9) & (recording.t <= recording.end_time + 1e-9))[::self.every]:
                features, frame, scale = window_features(recording.t, recording.position, recording.velocity, k)
                X.append(features)
                Y.append((((truth(recording, k) - recording.position[k]) @ frame.T) / scale).ravel())
        X, Y = np.array(X), np.array(Y)
        with ThreadpoolController().limit(limits=1, user_api="openmp"):    # reproducible, one core
            self.models = [HistGradientBoostingRegressor(max_iter=self.max_iter, early_stopping=False,
                                                         random_state=self.seed).fit(X, Y[:, j]) for j in range(Y.shape[1])]
        self.trained_on = tuple(r.name for r in recordings)
        return self

    def predict(self, recording, k: int) -> np.ndarray:
        """Where the hand will be at +LEADS s from the recording's sample k, from samples 0 … k: (len(LEADS), d) m."""
        features, frame, scale = window_features(recording.t, recording.position, recording.velocity, k)
        offsets = np.array([model.predict(features[None])[0] for model in self.models]).reshape(len(LEADS), -1)
        return recording.position[k] + scale * offsets @ frame


def leave_one_person_out(people: dict[str, list], fit):
    """For each person: (person, ``fit(recordings of every other person)``)."""
    for person in people:
        yield person, fit([r for other, recordings in people.items() if other != person for r in recordings])


def people_models(people: dict[str, list], cache: Path | None = None, log=sys.stderr) -> dict:
    """{person: the ``arm`` people model (:class:`~comanip.estimation.people.people_model.PeopleModel`) fitted on every
    other person's reaches} (:func:`leave_one_person_out`). ``cache``: a folder where each fit is kept as
    ``<reaches>-<digest>.npz``, the count and a digest of the names of the reaches it was fitted on and of the features
    an arm model reads and of how its fit weighs them, and read back by the next run on the same reaches, features and
    weighting (a fit takes seconds to a minute)."""
    import hashlib

    from comanip.estimation.people.people_model import KINDS, WEIGHTING, PeopleModel

    def fit(recordings):
        names = sorted(r.name for r in recordings)
        path = None
        if cache is not None:
            digest = hashlib.sha256("\n".join([*names, *KINDS["arm"], WEIGHTING["arm"]]).encode()).hexdigest()[:12]
            path = cache / f"{len(names)}-{digest}.npz"
            if path.is_file():
                return PeopleModel.load(path)
        print(f"  fitting the people model on {len(recordings)} reaches of the other people ...", flush=True, file=log)
        model = PeopleModel.fit(recordings, kind="arm")
        if path is not None:
            cache.mkdir(parents=True, exist_ok=True)
            model.save(path)
        return model

    return dict(leave_one_person_out(people, fit))


def comanip_paths(recording, people_model, ks) -> dict[int, np.ndarray]:
    """{k: where comanip's forecast puts the hand at +LEADS s from sample k (len(LEADS), d) m}, the online estimator
    (``arm`` preset, ``people_model``) fed every sample up to the largest k; a k without a forecast is left out."""
    import comanip
    from comanip.estimation import OnlineOptions

    model = comanip.presets.load("arm")
    estimator = comanip.OnlineGoalEstimator(model, np.r_[recording.position[0], np.zeros(model.state_size - model.n)],
                                            options=OnlineOptions(people_model=people_model))
    paths = {}
    for k in range(max(ks) + 1):
        estimate = estimator.update(float(recording.t[k]), recording.position[k], recording.velocity[k])
        if k in ks and estimate.forecast is not None:
            paths[k] = estimate.forecast.at(recording.t[k] + np.array(LEADS)).position
    return paths


def score_person(person: str, recordings, learned: LearnedForecaster, people_model=None) -> list[dict]:
    """One row per reach, start fraction, lead and forecaster for one left-out person."""
    rows = []
    for recording in recordings:
        ks = {f: recording.seen_until(f) - 1 for f in FROM}
        ours = comanip_paths(recording, people_model, set(ks.values())) if people_model is not None else {}
        for f, k in ks.items():
            if k < 1:
                continue
            recorded = truth(recording, k)
            paths = kinematic_paths(recording, k) | {LEARNED: learned.predict(recording, k)}
            if k in ours:
                paths[COMANIP] = ours[k]
            for forecaster, path in paths.items():
                for i, lead in enumerate(LEADS):
                    rows.append({"person": person, "movement": recording.name, "forecaster": forecaster, "from": f,
                                 "lead_s": lead, "distance_m": recording.distance,
                                 "error": float(np.linalg.norm(path[i] - recorded[i])) / recording.distance})
    return rows


def medians(rows, forecasters, people) -> dict:
    """{from: {person or "all people": {forecaster: [median error / D at each lead]}}}, the median over a person's
    reaches, "median over people" the median of the people's, "all reaches" over every reach."""
    table = {}
    for f in FROM:
        table[f] = {}
        for who in [*people, "median over people", "all reaches"]:
            table[f][who] = {}
            for forecaster in forecasters:
                cells = []
                for lead in LEADS:
                    if who == "median over people":
                        errors = [table[f][p][forecaster][LEADS.index(lead)] for p in people]
                    else:
                        errors = [r["error"] for r in rows if r["forecaster"] == forecaster and r["from"] == f
                                  and r["lead_s"] == lead and (who == "all reaches" or r["person"] == who)]
                    cells.append(float(np.nanmedian(errors)) if errors else float("nan"))
                table[f][who][forecaster] = cells
    return table


def markdown(table, forecasters, counts) -> str:
    """The tables: one per start fraction, a row per person, a cell per forecaster with its three leads."""
    people = list(counts)
    lines = [f"Where the hand will be, error / D at +{' / +'.join(f'{s:.1f}' for s in LEADS)} s (median over a person's "
             f"reaches), leave-one-person-out over {len(people)} arm people ({sum(counts.values())} reaches): the learned "
             f"forecaster" + (" and comanip's people model" if COMANIP in forecasters else "")
             + " fitted on the other people only"]
    for f in FROM:
        lines += ["", f"From {int(100 * f)} % of MT:", "",
                  "| person | reaches | " + " | ".join(forecasters) + " |", "|---|---|" + "---|" * len(forecasters)]
        for who, row in table[f].items():
            count = counts.get(who, sum(counts.values()) if who == "all reaches" else "")
            label = f"**{who}**" if who not in counts else who
            lines.append(f"| {label} | {count} | " + " | ".join(" / ".join(f"{e:.3f}" for e in row[name])
                                                              for name in forecasters) + " |")
        below = [p for p in people if all(table[f][p][LEARNED][i] < table[f][p][k][i]
                                          for k in KINEMATIC for i in range(len(LEADS)))]
        lines += ["", f"The learned forecaster is below every kinematic forecaster at every lead from {int(100 * f)} % "
                      f"of MT for {len(below)} of {len(people)} people."]
    return "\n".join(lines)


def main(argv=None):
    parser = add_people_arguments(argparse.ArgumentParser(description=__doc__.split("\n\n")[0]))
    parser.add_argument("--limit", type=int, default=None, help="at most this many reaches per person")
    parser.add_argument("--every", type=int, default=1, help="train the learned forecaster on every N-th sample (default: %(default)s)")
    parser.add_argument("--max-iter", type=int, default=200, help="boosting iterations per tree ensemble (default: %(default)s)")
    parser.add_argument("--comanip", action="store_true", help="also score comanip's forecast (the people model fitted per fold)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "forecast_peers")
    parser.add_argument("--markdown", action="store_true", help="print only the tables on stdout (progress on stderr)")
    args = parser.parse_args(argv)
    if args.limit is not None and args.limit < 1 or args.every < 1 or args.max_iter < 1:
        parser.error("--limit, --every and --max-iter must be whole numbers ≥ 1")
    log = sys.stderr if args.markdown else sys.stdout
    begin = time.perf_counter()
    people = people_of(args, parser, args.limit)
    counts = {person: len(recordings) for person, recordings in people.items()}
    print(f"{len(people)} people, {sum(counts.values())} reaches read in {time.perf_counter() - begin:.0f} s", file=log, flush=True)
    from comanip.estimation.people.people_model import PeopleModel

    def fit(recordings):
        return (LearnedForecaster(max_iter=args.max_iter, every=args.every).fit(recordings),
                PeopleModel.fit(recordings, kind="arm") if args.comanip else None)

    rows = []
    for i, (person, (learned, people_model)) in enumerate(leave_one_person_out(people, fit)):
        rows += score_person(person, people[person], learned, people_model)
        print(f"  {i + 1}/{len(people)} {person} left out: trained on {len(learned.trained_on)} reaches, "
              f"{time.perf_counter() - begin:.0f} s", file=log, flush=True)
    forecasters = [*KINEMATIC, LEARNED] + ([COMANIP] if args.comanip else [])
    table = medians(rows, forecasters, list(people))
    text = markdown(table, forecasters, counts)
    print(text)
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "errors.csv", "w", newline="") as stream:
        writer = csv.DictWriter(stream, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    (args.out / "summary.json").write_text(json.dumps({"leads_s": LEADS, "from": FROM, "reaches": counts,
                                                       "median_error_over_D": {str(f): v for f, v in table.items()}},
                                                      indent=1))
    (args.out / "summary.md").write_text(text + "\n")
    print(f"wrote {args.out}", file=log)


if __name__ == "__main__":
    main()
