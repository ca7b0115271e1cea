"""Can the reaching model add anything to the people model's goal on recorded arm reaches?

Three ways the model's reach could carry, or help, the estimate, each scored on the development arm reaches
streamed as a live tracker delivers them (as in benchmarks/real_people.py --source arms), every reach with a
people model fitted on the other half of the split (the reaches of the other parity):

1. **A shape fitted at the person's pace.** The goal from fitting a speed profile's shape to the hand so far
   (variable projection over movement time and onset, log T ~ N(log T_ref, 0.35²), as
   :func:`comanip.estimation.model_reaches.profile_fit.fit_profile`): x(t) = x_0 + Delta r(phi) along a straight line, or
   with a bow, + B 4 r(phi) (1 - r(phi)), which leaves the start and reaches the goal along a curved path.
   Two shapes: the `arm` preset's mean reach (T_ref its movement time) and, as a ceiling for a model's mean
   reach fitted this way, the recorded people's own mean profile along their line (T_ref their median
   movement time), both from the other half.
2. **A blend.** The people model's goal moved a fraction w of the way to the estimator's paced fit
   (:class:`comanip.estimation.model_reaches.paced_model.PacedModel`), for the best w.
3. **The model as features.** The people model's along regressor (the share of the path still to go) given
   the paced fit's goal (along and across the direction of motion, over the path so far), its log pace and log
   misfit beside its own features.

Printed as a markdown block (progress on stderr): error / D, median, at 25/50/75/90 % of the movement time,
and each shape fit's misfit (chi² per observed number; the estimator accepts at most 0.05).

    PYTHONPATH=src python -m studies.does_the_reaching_model_add_to_the_arm_estimate.measure_model_share [--limit N]
"""

from __future__ import annotations

import math
import sys

import numpy as np

import comanip
from comanip.estimation.people.endpoint_baselines import MOVING_SPEED
from comanip.estimation.model_reaches.paced_model import PACE_STD, PacedModel
from comanip.estimation.people.people_model import (FEATURES, KINDS, WEIGHTING, PeopleModel, _along_regressor, beyond_over_path,
                                             movement_features, share_to_go)
from comanip.estimation.model_reaches.profile_fit import detected_onset
from comanip.estimation.model_reaches.reach_profile import ReachProfile

from studies.arm_reaches import streamed_arm_reaches  # noqa: E402

FRACTIONS = (0.25, 0.5, 0.75, 0.9)
BLENDS = (0.1, 0.2, 0.3, 0.5)
PHASE = np.linspace(0.0, 1.0, 201)


def people_shape(recordings) -> tuple[ReachProfile, float]:
    """The recordings' mean progress along their line, r(phi) from onset to end, and their median movement time (s)."""
    fractions, rates = [], []
    for r in recordings:
        inside = (r.t >= r.onset) & (r.t <= r.end_time)
        t, p, v = r.t[inside], r.position[inside], r.velocity[inside]
        line = p[-1] - p[0]
        D = float(np.linalg.norm(line))
        phi = (t - t[0]) / (t[-1] - t[0])
        fractions.append(np.interp(PHASE, phi, (p - p[0]) @ line / D**2))
        rates.append(np.interp(PHASE, phi, v @ line / D**2 * (t[-1] - t[0])))
    r, dr = np.mean(fractions, axis=0), np.mean(rates, axis=0)
    return ReachProfile(PHASE, r / r[-1], dr / r[-1], "recorded people"), float(np.median([r.movement_time for r in recordings]))


def shape_fit(t, offset, velocity, shape: ReachProfile, onset: float, reference_time: float, bow: bool):
    """(Delta (d,) m, misfit) of ``shape`` fitted to positions relative to the start (K, d) m and velocities
    (K, d) m/s, with an optional bow term (module docstring): the posterior mean of Delta over a grid of movement
    times (0.1–4 s) and onsets (±0.15 s around ``onset``)."""
    wx = 1.0 / (0.03 * max(float(np.sqrt((offset * offset).sum(axis=1).max())), 1e-6)) ** 2
    wv = 1.0 / (0.1 * max(float(np.sqrt((velocity * velocity).sum(axis=1).max())), 1e-6)) ** 2
    total = wx * (offset * offset).sum() + wv * (velocity * velocity).sum()
    log_T, t0 = (a.ravel() for a in np.meshgrid(np.log(np.geomspace(0.1, 4.0, 80)), onset + np.linspace(-0.15, 0.15, 31),
                                                indexing="ij"))
    T = np.exp(log_T)
    r, dr = shape((t[None, :] - t0[:, None]) / T[:, None])
    dr = dr / T[:, None]
    basis, rates = (np.stack([r, 4 * r * (1 - r)], axis=1), np.stack([dr, 4 * dr * (1 - 2 * r)], axis=1)) if bow else \
        (r[:, None], dr[:, None])
    normal = wx * np.einsum("gik,gjk->gij", basis, basis) + wv * np.einsum("gik,gjk->gij", rates, rates)
    normal += 1e-12 * np.eye(basis.shape[1])
    projected = wx * np.einsum("gik,kd->gid", basis, offset) + wv * np.einsum("gik,kd->gid", rates, velocity)
    coefficients = np.linalg.solve(normal, projected)
    chi2 = np.maximum(total - np.einsum("gid,gid->g", coefficients, projected), 0.0)
    numbers = offset.size + velocity.size
    s2 = max(float(chi2.min()) / max(numbers - offset.shape[1] - 2, 1), 0.01)
    log_weight = -0.5 * (chi2 - chi2.min()) / s2 - 0.5 * ((log_T - math.log(reference_time)) / PACE_STD) ** 2
    weight = np.exp(log_weight - log_weight.max())
    return weight @ coefficients[:, 0] / weight.sum(), float(chi2.min()) / numbers


def paced_trace(recording, paced: PacedModel) -> dict:
    """{prefix length k: (scale-free features, u, L, the paced fit's goal (d,) m, its features (4,))} from the
    onset on, each paced fit started at the distance the previous one found (as the estimator does)."""
    start, speed = recording.position[0], np.linalg.norm(recording.velocity, axis=1)
    columns = [FEATURES.index(name) for name in KINDS["arm"]]
    trace, previous = {}, None
    for k in range(2, len(recording.t) + 1):
        described = movement_features(recording.t[:k], recording.position[:k], recording.velocity[:k], start)
        if described is None:
            continue
        features, u, path = described
        displacement = max(float(np.linalg.norm(recording.position[k - 1] - start)), 1e-3)
        fit = paced.fit(recording.t[:k], recording.position[:k], recording.velocity[:k], start,
                        detected_onset(recording.t[:k], speed[:k], MOVING_SPEED), [previous or 1.5 * displacement])
        previous = float(np.linalg.norm(fit.goal - start))
        offset = fit.goal - recording.position[k - 1]
        along = float(offset @ u)
        trace[k] = (features[columns], u, path, fit.goal,
                    np.array([along / path, float(np.linalg.norm(offset - along * u)) / path, math.log(fit.pace),
                              math.log(fit.misfit + 1e-9)]))
    return trace


def main(argv=None) -> None:
    recordings = streamed_arm_reaches(__doc__.split("\n\n")[0], argv)
    model = comanip.presets.arm()
    paced = PacedModel(comanip.OnlineGoalEstimator(model, np.zeros(model.state_size)).family)
    model_shape = paced.shape(float(np.median([r.distance for r in recordings])))
    print(f"paced fits on every sample of {len(recordings)} reaches ...", file=sys.stderr, flush=True)
    traces = [paced_trace(r, paced) for r in recordings]
    errors: dict[str, dict[float, list]] = {}
    misfits: dict[str, list] = {}

    def score(name, goal, recording, fraction, misfit=None):
        errors.setdefault(name, {f: [] for f in FRACTIONS})[fraction].append(
            float(np.linalg.norm(goal - recording.end)) / recording.distance)
        if misfit is not None and fraction == 0.5:
            misfits.setdefault(name, []).append(misfit)

    for parity in (0, 1):
        print(f"half {parity + 1} of 2 ...", file=sys.stderr, flush=True)
        train = [k for k in range(len(recordings)) if k % 2 != parity]
        people = PeopleModel.fit([recordings[k] for k in train], kind="arm")
        shape, movement_time = people_shape([recordings[k] for k in train])
        X, y, weights = [], [], []
        for k in train:
            for prefix, (features, u, path, _, extra) in traces[k].items():
                X.append(np.r_[features, extra])
                y.append(float((recordings[k].end - recordings[k].position[prefix - 1]) @ u) / path)
                weights.append(1.0 / len(traces[k]) if WEIGHTING["arm"] == "reach" else 1.0)   # as the people model's fit
        with_model = _along_regressor(np.array(X), share_to_go(np.array(y)), 0, np.array(weights) * len(weights) / sum(weights))
        for k in range(parity, len(recordings), 2):
            r = recordings[k]
            speed = np.linalg.norm(r.velocity, axis=1)
            for fraction in FRACTIONS:
                n = max(r.seen_until(fraction), 2)
                t, offset, velocity = r.t[:n], r.position[:n] - r.position[0], r.velocity[:n]
                onset = detected_onset(t, speed[:n], MOVING_SPEED)
                for label, profile, reference, scale in (
                        ("the arm preset's mean reach", model_shape.profile, model_shape.duration, model_shape.goal_over_end),
                        ("the people's mean profile (ceiling)", shape, movement_time, 1.0)):
                    for bow in (False, True):
                        delta, misfit = shape_fit(t, offset, velocity, profile, onset, reference, bow)
                        score(f"{label}, {'with a bow' if bow else 'straight'}", r.position[0] + scale * delta, r, fraction, misfit)
                said = people.predict(t, r.position[:n], velocity, r.position[0]).goal
                score("the people model", said, r, fraction)
                if n in traces[k]:
                    features, u, path, paced_goal, extra = traces[k][n]
                    for w in BLENDS:
                        score(f"blend w = {w:g}", said + w * (paced_goal - said), r, fraction)
                    along = max(float(beyond_over_path(with_model.predict(np.r_[features, extra][None]))[0]), 0.0)
                    score("the people model with the paced fit as features", r.position[n - 1] + path * along * u, r, fraction)
    blends = {name: cells for name, cells in errors.items() if name.startswith("blend")}
    best = min(blends, key=lambda name: np.mean([np.median(v) for v in blends[name].values()]))
    print(f"The reaching model beside the people model on the development arm reaches ({len(recordings)}, streamed at "
          "125 Hz; each reach scored with fits on the other half): goal error / D, median; misfit at 50 % of MT "
          "(chi² per observed number, median; the estimator accepts ≤ 0.05)\n")
    print("| predictor | " + " | ".join(f"{100 * f:g} % of MT" for f in FRACTIONS) + " | misfit |")
    print("|---|" + "---|" * (len(FRACTIONS) + 1))
    for name, cells in errors.items():
        if name.startswith("blend") and name != best:
            continue
        label = f"the people model moved towards the paced fit, best {name}" if name == best else name
        misfit = f"{np.median(misfits[name]):.3f}" if name in misfits else ""
        print(f"| {label} | " + " | ".join(f"{np.median(v):.3f}" for v in cells.values()) + f" | {misfit} |")


if __name__ == "__main__":
    main()
