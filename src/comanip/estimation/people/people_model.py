"""Where a person's moving hand will stop: a model fitted to recorded people's movements.

From the movement so far (times t_k s, positions x_k m, velocities v_k m/s, k ≤ K, from a hand at rest at
x_0) :func:`movement_features` computes numbers that say how far along its movement the hand is, most of
them without units: time since the onset tau, path length since the onset L, the speed now over the peak
speed so far, the acceleration, time since the peak speed over tau, the path length at the peak over L, the
straightness |x_K - x_0| / L, the angle between the velocity and the displacement, and v_peak tau / L.
Gradient-boosted regressors (scikit-learn, fitted on recordings by :meth:`PeopleModel.fit`) predict from
them how far beyond the hand the endpoint lies along the direction of motion u (the velocity's while the hand
moves, ``DIRECTION_SPEED``; near rest its displacement over the last ``DIRECTION_WINDOW`` s), the log of the
expected squared error, and when the hand stops: log(r / tau + ``REMAINING_FLOOR``) for the time r still to go
(s). How far beyond the hand is regressed as the share of the whole path still to go, s = a / (1 + |a|) for
the distance beyond the hand over L, a: s lies in (-1, 1), while a runs to thousands a few samples after the
onset (L of a millimetre or two), and trees fitted to a let such values leak into predictions mid-movement.
The predicted
endpoint is never behind the hand along u, and a hand that has stopped (its positions still for a tenth of a
second after it left the start and its net speed over that time below half ``REST_FRACTION`` of its peak speed,
:mod:`comanip.estimation.hand_rest`, or its speed below ``REST_FRACTION`` of its peak for ``REST_TIME``) is at its
endpoint. Its covariance is isotropic: the predicted squared error times a
factor that makes the 95 % region hold 95 % of the fitting samples' endpoints (errors and their predicted
spread both out of sample; the samples weighted as the fit weighs them, :data:`WEIGHTING`: for an arm, every reach
alike, whatever its tracker's rate and its duration), one factor for each phase of the movement (:data:`PHASE_BINS`: bins of the predicted
share still to go, s, each holding as many fitting samples), so that the region holds as often near the end as
early on; and while the path so far is short, never below the distance the hand can still cover at its speed
(``STOPPING_TIME``).

A model is fitted per **kind** of movement (:data:`KINDS`): people move a mouse and an arm differently, and a
model fitted on one is not applied to the other. An arm model uses only features without units
(:data:`ARM_FEATURES`, of :data:`SCALE_FREE`): fitted on reaches of one length and pace, it predicts in units of
the path so far and of the time since the onset, so it carries over to other distances and paces as far as
people's profiles keep their shape. Of the features without units it leaves out the straightness: fitted on
other people without it, its goal moves less from one sample to the next and is as near. The straightness reads
the tracker as much as the hand: it sets the displacement against a path integrated from velocities derived
over a window, so a short reach's differs from a long one's of the same shape, and a noisy tracker's
path is longer. A model reads the features it names (:attr:`PeopleModel.features`), saved with it.

Models are saved as plain arrays (``.npz``: every tree's nodes, :class:`TreeEnsemble`) and loaded without
scikit-learn (:meth:`PeopleModel.load`). Two ship with comanip (``comanip/data/people_endpoint_<kind>.npz``):
``mouse``, fitted on the development split of the ``cursory`` mouse recordings mapped to arm scale
(:mod:`comanip.recordings.cursory_data`), and ``arm``, fitted on motion-capture arm reaches
(:mod:`comanip.recordings.motion_capture`); ``studies/how_far_beyond_the_hand_do_people_stop/fit_people_model.py``
fits them again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from comanip.caching.process_caches import PROCESS_CACHES
from comanip.estimation.people.endpoint_baselines import MOVING_SPEED, EndpointPrediction
from comanip.estimation.hand_rest import has_left, resting_position
from comanip.estimation.model_reaches.profile_fit import onset_index

FEATURES = ("tau_s", "path_m", "speed_m_s", "peak_speed_m_s", "speed_over_peak", "acceleration_scaled",
            "since_peak_over_tau", "path_at_peak_over_path", "straightness", "direction_cosine", "peak_speed_tau_over_path")
"""Names of :func:`movement_features`' numbers, in order."""
SCALE_FREE = ("speed_over_peak", "acceleration_scaled", "since_peak_over_tau", "path_at_peak_over_path", "straightness",
              "direction_cosine", "peak_speed_tau_over_path")
"""The features without units (neither m nor s): what an ``arm`` model uses."""
ARM_FEATURES = tuple(name for name in SCALE_FREE if name != "straightness")
"""The features an ``arm`` model is fitted on: :data:`SCALE_FREE` but the straightness (module docstring), chosen
leave-one-person-out on recorded arm people (``studies/which_movement_features_carry_across_people``)."""
KINDS = {"mouse": FEATURES, "arm": ARM_FEATURES}
"""Kinds of movement a people model is fitted to, and the features a model of each is fitted on."""
PHASE_BINS = {"mouse": 1, "arm": 5}
"""How many phases of the movement (bins of the predicted share still to go) a model of each kind calibrates its
95 % region on, each with its own coverage factor; the arm's chosen leave-one-person-out on recorded arm people
(``studies/does_a_region_per_phase_hold_for_new_people``)."""
WEIGHTING = {"mouse": "sample", "arm": "reach"}
"""How a fit of each kind weighs its recordings' samples: ``"sample"``, every sample alike (a recording at a higher
rate, or of a longer movement, counts more), or ``"reach"``, every recording alike (its samples share a weight of
one); the arm's chosen leave-one-person-out on recorded arm people, whose trackers and paces differ
(``studies/should_every_reach_weigh_alike``)."""
UNNAMED_FEATURES = {"mouse": FEATURES, "arm": SCALE_FREE}
"""The features a model of each kind read when its file did not name them (saved before models named theirs)."""
DIRECTION_SPEED = 0.1
"""The direction of motion u is the velocity's while the speed is above this fraction of its peak so far..."""
DIRECTION_WINDOW = 0.05
"""... else that of the hand's displacement over the last this many seconds (s), else from the start."""
QUANTILE = 0.3
"""The along regressor predicts this quantile of the distance still to go: below the median, since a goal
predicted beyond where the hand stops costs a robot more than one predicted short of it."""
REST_FRACTION, REST_TIME = 0.05, 0.1
"""A hand whose speed has stayed below this fraction of its peak speed for this long (s) has stopped."""
STOPPING_TIME = 0.1
"""A hand moving at speed v can still cover about v times this (s) before it stops. While its path so far is
shorter than that, the movement says little (a sample or two after the onset) and the predicted endpoint's
standard deviation (per axis) is never below it, whatever the regressors say."""
REMAINING_FLOOR = 0.02
"""Added to the time still to go over tau before its log is regressed (a hand at its end has none to go)."""
REST_SPREAD = 0.03
"""Standard deviation of a stopped hand's endpoint estimate, a fraction of the path length."""
MAX_SHARE = 0.999
"""The largest share of the path still to go a prediction is taken at (a = 999 path lengths)."""
_MIN_PATH = 1e-4
_MIN_RECENT = 2e-3


def checked_features(kind: str, features=None) -> tuple[str, ...]:
    """The names of the features a model of ``kind`` reads: ``features`` (names of :data:`FEATURES`, distinct;
    for an arm, of :data:`SCALE_FREE`) or, for None, the kind's (:data:`KINDS`); a one-line ValueError otherwise."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {sorted(KINDS)}, got {kind!r}")
    named = KINDS[kind] if features is None else tuple(str(name) for name in features)
    if not named or len(set(named)) < len(named) or not set(named) <= set(FEATURES):
        raise ValueError(f"features must name distinct movement features of {FEATURES}, got {named!r}")
    if kind == "arm" and not set(named) <= set(SCALE_FREE):
        raise ValueError(f"an arm model reads features without units only (of {SCALE_FREE}), got {named!r}")
    return named


def movement_features(t: np.ndarray, position: np.ndarray, velocity: np.ndarray, start: np.ndarray):
    """(features (len(FEATURES),), direction u (d,), path length L m) of the movement so far, or None before its onset.

    Args:
        t: times (K,), s; position: (K, d) m; velocity: (K, d) m/s; start: rest position x_0 (d,), m.
    """
    speed = np.sqrt((velocity * velocity).sum(axis=1))
    first = onset_index(speed, MOVING_SPEED)
    if first is None:
        return None
    covered = np.r_[0.0, np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))]
    path = covered[-1] - covered[first] + _MIN_PATH
    tau = t[-1] - t[first] + 1e-3
    peak = int(np.argmax(speed))
    offset = position[-1] - start
    displacement = math.sqrt(float(offset @ offset))
    recent = position[-1] - position[int(np.searchsorted(t, t[-1] - DIRECTION_WINDOW))]
    recent_length = math.sqrt(float(recent @ recent))
    if speed[-1] > DIRECTION_SPEED * speed[peak]:
        u = velocity[-1] / speed[-1]
    elif recent_length > _MIN_RECENT:
        u = recent / recent_length
    elif displacement > 0:
        u = offset / displacement
    else:
        u = np.eye(len(start))[0]
    acceleration = (speed[-1] - speed[-2]) / (t[-1] - t[-2]) if len(t) > 1 and t[-1] > t[-2] else 0.0
    features = np.array([tau, path, speed[-1], speed[peak], speed[-1] / speed[peak], acceleration * tau / speed[peak],
                         (t[-1] - t[peak]) / tau, (covered[peak] - covered[first]) / path, displacement / path,
                         float(u @ offset) / displacement if displacement > 0 else 1.0, speed[peak] * tau / path])
    return features, u, path


@dataclass(frozen=True)
class PeopleModel:
    """The fitted endpoint model (module docstring)."""

    along: "TreeEnsemble"
    """Regressor of the share of the path still to go along u, s = a / (1 + |a|) with a the endpoint's distance
    beyond the hand along u over L (its ``QUANTILE`` quantile); ``along_target`` says which."""
    spread: "TreeEnsemble"
    """Regressor of log(|error|² / L²) from the features."""
    coverage_factor: float
    """Multiplies the predicted squared error so the 95 % region holds 95 % of the fitting samples' endpoints (of
    every phase; where ``phase_factors`` are given, they replace it)."""
    kind: str = "mouse"
    """The kind of movement it was fitted to, a key of :data:`KINDS`."""
    trained_on: str = ""
    """What the model was fitted on."""
    remaining: "TreeEnsemble | None" = None
    """Regressor of log(time still to go / tau + ``REMAINING_FLOOR``); None: the model does not say when."""
    along_target: str = "share"
    """What ``along`` predicts, a key of :data:`ALONG_TARGETS`: ``share`` (s) or, in models saved before it
    existed, ``over path`` (a itself)."""
    features: tuple[str, ...] | None = None
    """Names (of :data:`FEATURES`, in the order its trees read them) of the features the model reads; None: those
    of its kind (:data:`KINDS`)."""
    phase_edges: tuple[float, ...] = ()
    """Bounds of the phases (P - 1 increasing values of the predicted share still to go s, in (-1, 1))."""
    phase_factors: tuple[float, ...] = ()
    """The coverage factor of each phase (P values > 0, from the phase nearest the end, lowest s, on); empty: the
    one ``coverage_factor``."""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {sorted(KINDS)}, got {self.kind!r}")
        if self.along_target not in ALONG_TARGETS:
            raise ValueError(f"along_target must be one of {sorted(ALONG_TARGETS)}, got {self.along_target!r}")
        object.__setattr__(self, "features", checked_features(self.kind, self.features))
        edges, factors = tuple(float(e) for e in self.phase_edges), tuple(float(f) for f in self.phase_factors)
        if factors and (len(edges) != len(factors) - 1 or np.any(np.diff(edges) <= 0)
                        or not all(math.isfinite(f) and f > 0 for f in factors)):
            raise ValueError(f"phase_factors must be P > 0 factors and phase_edges P - 1 increasing shares, got "
                             f"{factors!r} and {edges!r}")
        if edges and not factors:
            raise ValueError(f"phase_edges need phase_factors, got edges {edges!r} alone")
        object.__setattr__(self, "phase_edges", edges)
        object.__setattr__(self, "phase_factors", factors)
        read = max((int(e.feature[~e.leaf].max(initial=0)) for e in (self.along, self.spread, self.remaining) if e is not None))
        if read >= len(self.features):
            raise ValueError(f"the trees read feature {read}, but the model names {len(self.features)} features")
        object.__setattr__(self, "_trees", StackedTrees([e for e in (self.along, self.spread, self.remaining) if e is not None]))

    @property
    def columns(self) -> np.ndarray:
        """Indices into :data:`FEATURES` of the features this model reads."""
        return np.array([FEATURES.index(name) for name in self.features])

    @classmethod
    def fit(cls, recordings, kind: str = "mouse", trained_on: str = "", seed: int = 0, progress=None,
            features=None, phases: int | None = None, weights=None) -> "PeopleModel":
        """Fit on recordings (:class:`comanip.recordings.Recording`) of one ``kind`` of movement, every sample
        from each one's onset to its end: the spread regressor on two-fold out-of-sample errors of the along
        regressor, and the coverage factor on those errors over the spread each fold's spread regressor predicts
        for the other fold (a spread fitted on the very errors it is scored on predicts them too well), then
        the along, spread and remaining-time regressors on all samples. ``progress``: called with a line of
        text per stage. ``features``: names of :data:`FEATURES` to fit on (default: the kind's, :data:`KINDS`).
        ``phases``: how many phases get their own coverage factor (≥ 1; default: the kind's, :data:`PHASE_BINS`).
        ``weights``: ``"sample"`` (every sample counts alike), ``"reach"`` (every recording counts alike, its weight
        shared among its samples), how much each recording counts (len(recordings),), ≥ 0, shared among its samples
        (e.g. one over a person's count of recordings, so that every person counts alike), or None: the kind's
        (:data:`WEIGHTING`). Needs scikit-learn."""
        from threadpoolctl import ThreadpoolController
        features = checked_features(kind, features)
        if len(recordings) < 4:
            raise ValueError(f"PeopleModel.fit needs at least 4 recordings (two folds of two), got {len(recordings)}")
        phases = PHASE_BINS[kind] if phases is None else phases
        if isinstance(phases, bool) or not isinstance(phases, (int, np.integer)) or phases < 1:
            raise ValueError(f"phases must be a whole number ≥ 1, got {phases!r}")
        weights = WEIGHTING[kind] if weights is None else weights
        if isinstance(weights, str):
            if weights not in ("sample", "reach"):
                raise ValueError(f"weights must be 'sample', 'reach' or one number per recording, got {weights!r}")
            weights = None if weights == "sample" else np.ones(len(recordings))
        else:
            weights = np.asarray(weights, dtype=float)
            if weights.shape != (len(recordings),) or not np.all(np.isfinite(weights)) or np.any(weights < 0) or not weights.any():
                raise ValueError(f"weights must be {len(recordings)} finite numbers ≥ 0 (one per recording), not all 0, "
                                 f"got shape {weights.shape}")
        with ThreadpoolController().limit(limits=1, user_api="openmp"):   # reproducible, no spinning threads
            return cls._fit(recordings, kind, features, int(phases), weights, trained_on, seed, progress or (lambda line: None))

    @classmethod
    def _fit(cls, recordings, kind: str, features: tuple, phases: int, weights, trained_on: str, seed: int,
             say) -> "PeopleModel":
        from sklearn.ensemble import HistGradientBoostingRegressor
        X, along, across, remaining, owner = _samples(recordings)
        X = X[:, [FEATURES.index(name) for name in features]]
        w = None
        if weights is not None:
            counts = np.bincount(owner, minlength=len(recordings))
            if not weights[counts > 0].any():
                raise ValueError("weights give no weight to any recording that moves")
            w = weights[owner] / counts[owner] * len(X) / weights[counts > 0].sum()   # mean 1 over the samples

        def part(mask):
            return None if w is None else w[mask]
        fold = np.random.default_rng(seed).permutation(len(recordings))[owner] % 2
        share = np.zeros(len(X))
        for k in (0, 1):
            say(f"along regressor, fold {k + 1} of 2 ({int((fold != k).sum())} samples)")
            share[fold == k] = _along_regressor(X[fold != k], share_to_go(along[fold != k]), seed,
                                                part(fold != k)).predict(X[fold == k])
        predicted = beyond_over_path(share)
        squared = (np.maximum(predicted, 0.0) - along) ** 2 + across**2
        log_squared = np.log(squared + 1e-6)
        spread_out_of_sample = np.zeros(len(X))
        for k in (0, 1):
            say(f"spread regressor, fold {k + 1} of 2")
            spread_out_of_sample[fold == k] = _spread_regressor(X[fold != k], log_squared[fold != k], seed,
                                                                part(fold != k)).predict(X[fold == k])
        d = recordings[0].position.shape[1]
        ratio = squared / np.exp(spread_out_of_sample) / chi2.ppf(0.95, d) * d
        factor = weighted_quantile(ratio, 0.95, w)
        edges = np.unique(weighted_quantile(share, np.arange(1, phases) / phases, w)) if phases > 1 else np.zeros(0)
        phase = np.searchsorted(edges, share)
        factors = tuple(weighted_quantile(ratio[phase == i], 0.95, part(phase == i)) if np.any(phase == i) else factor   # ties
                        for i in range(len(edges) + 1)) if len(edges) else ()
        say("spread regressor, all samples")
        spread = _spread_regressor(X, log_squared, seed, w)
        say("along regressor, all samples")
        along_regressor = _along_regressor(X, share_to_go(along), seed, w)
        say("remaining-time regressor")
        remaining_regressor = HistGradientBoostingRegressor(max_iter=100, learning_rate=0.1, random_state=seed).fit(
            X, np.log(remaining + REMAINING_FLOOR), sample_weight=w)
        return cls(TreeEnsemble.of(along_regressor), TreeEnsemble.of(spread), factor, kind, trained_on,
                   TreeEnsemble.of(remaining_regressor), features=features, phase_edges=tuple(edges), phase_factors=factors)

    def predict(self, t, position, velocity, start) -> EndpointPrediction | None:
        """The endpoint (d,) m and its covariance (d, d) m² from the movement so far (:func:`movement_features`'
        arguments), or None before the onset."""
        described = movement_features(t, position, velocity, start)
        if described is None:
            return None
        features, u, path = described
        speed = np.sqrt((velocity * velocity).sum(axis=1))
        # a hand that has stopped is at its endpoint (until it moves again)
        stopped = (REST_SPREAD * path) ** 2 / len(u) * np.eye(len(u))
        resting = resting_position(t, position, creep=0.5 * REST_FRACTION * features[3])
        if resting is not None and has_left(position, start):
            return EndpointPrediction(resting, stopped, float(t[-1]))
        if t[-1] - t[np.flatnonzero(speed > REST_FRACTION * features[3])[-1]] >= REST_TIME:
            return EndpointPrediction(position[-1].copy(), stopped, float(t[-1]))
        x = features[self.columns]
        predicted = self._trees(x)
        along, log_squared = float(ALONG_TARGETS[self.along_target](predicted[0])), float(predicted[1])
        goal = position[-1] + path * max(along, 0.0) * u
        variance = self.factor_at(float(predicted[0])) * path**2 * math.exp(log_squared) / len(u)
        if path < STOPPING_TIME * speed[-1]:
            variance = max(variance, (STOPPING_TIME * speed[-1]) ** 2)
        end_time = None if self.remaining is None else \
            float(t[-1]) + features[0] * max(math.exp(predicted[2]) - REMAINING_FLOOR, 0.0)
        return EndpointPrediction(goal, variance * np.eye(len(u)), end_time)

    def factor_at(self, share: float) -> float:
        """The coverage factor of the phase at the along regressor's prediction ``share`` (s, or for an ``over path``
        model a)."""
        if not self.phase_factors:
            return self.coverage_factor
        return self.phase_factors[int(np.searchsorted(self.phase_edges, share))]

    def save(self, path: str | Path) -> Path:
        """Write the model to ``path`` as plain arrays (``.npz``); :meth:`load` reads it back."""
        path = Path(path)
        arrays = {f"{name}_{field}": value for name in ("along", "spread", "remaining") if getattr(self, name) is not None
                  for field, value in getattr(self, name).arrays().items()}
        with open(path, "wb") as stream:
            np.savez_compressed(stream, coverage_factor=self.coverage_factor, kind=self.kind, trained_on=self.trained_on,
                                along_target=self.along_target, features=np.array(self.features),
                                phase_edges=np.array(self.phase_edges), phase_factors=np.array(self.phase_factors), **arrays)
        return path

    @classmethod
    def load(cls, path: str | Path) -> "PeopleModel":
        """A model written by :meth:`save` (a one-line ValueError for a file that is not one)."""
        try:
            with np.load(path, allow_pickle=False) as data:
                along, spread, remaining = (TreeEnsemble(**{field: data[f"{name}_{field}"] for field in TreeEnsemble.FIELDS})
                                            if f"{name}_feature" in data else None for name in ("along", "spread", "remaining"))
                if along is None or spread is None:
                    raise KeyError("along or spread regressor")
                target = str(data["along_target"]) if "along_target" in data else "over path"
                kind = str(data["kind"])
                features = tuple(str(name) for name in data["features"]) if "features" in data else UNNAMED_FEATURES.get(kind)
                phases = {name: tuple(data[name]) if name in data else () for name in ("phase_edges", "phase_factors")}
                return cls(along, spread, float(data["coverage_factor"]), kind, str(data["trained_on"]), remaining,
                           target, features, **phases)
        except (OSError, KeyError, ValueError) as error:
            raise ValueError(f"{str(path)!r} is not a people model written by PeopleModel.save ({error})") from None


class TreeEnsemble:
    """A fitted gradient-boosted regressor as arrays of its trees' nodes, evaluated on one row by walking all
    its trees at once (:class:`StackedTrees`): the same number as scikit-learn's ``predict`` of the regressor it
    came from (to rounding, a test checks), in tens of microseconds, and saved as plain arrays."""

    FIELDS = ("feature", "threshold", "left", "right", "leaf", "value", "baseline")

    def __init__(self, feature, threshold, left, right, leaf, value, baseline):
        self.feature, self.left, self.right = (np.asarray(a, dtype=np.intp) for a in (feature, left, right))
        self.threshold, self.value = np.asarray(threshold, dtype=float), np.asarray(value, dtype=float)
        self.leaf = np.asarray(leaf, dtype=bool)
        self.baseline = float(baseline)
        self.depth = self._depth()
        self._walk = StackedTrees((self,))

    @classmethod
    def of(cls, regressor) -> "TreeEnsemble":
        """The trees of a fitted scikit-learn ``HistGradientBoostingRegressor``."""
        trees = [predictors[0].nodes for predictors in regressor._predictors]
        shape = (len(trees), max(len(nodes) for nodes in trees))
        feature, left, right = (np.zeros(shape, dtype=np.intp) for _ in range(3))
        threshold, value, leaf = np.zeros(shape), np.zeros(shape), np.ones(shape, dtype=bool)
        for k, nodes in enumerate(trees):
            m = len(nodes)
            feature[k, :m], threshold[k, :m] = nodes["feature_idx"], nodes["num_threshold"]
            left[k, :m], right[k, :m] = nodes["left"], nodes["right"]
            leaf[k, :m], value[k, :m] = nodes["is_leaf"].astype(bool), nodes["value"]
        return cls(feature, threshold, left, right, leaf, value, float(np.ravel(regressor._baseline_prediction)[0]))

    def arrays(self) -> dict:
        """The arrays :meth:`__init__` takes, by name."""
        return {name: getattr(self, name) for name in self.FIELDS}

    def _depth(self) -> int:
        """Steps from the root to the deepest leaf, over all trees (a child's index is above its parent's)."""
        depth = np.zeros(self.feature.shape, dtype=np.intp)
        for i in range(self.feature.shape[1]):
            inner = np.flatnonzero(~self.leaf[:, i])
            depth[inner, self.left[inner, i]] = depth[inner, self.right[inner, i]] = depth[inner, i] + 1
        return int(depth.max())

    def __call__(self, x: np.ndarray) -> float:
        """The regressor's prediction for one row of finite features x (F,)."""
        return float(self._walk(x)[0])


class StackedTrees:
    """Several :class:`TreeEnsemble` s evaluated on one row together: their nodes in flat arrays, each child a flat
    index and each leaf its own child, so that one comparison of the row against every node's threshold and one
    step per level of the deepest tree walk every tree of every ensemble at once."""

    def __init__(self, ensembles):
        offsets, features, thresholds, lefts, rights, values, owners = [], [], [], [], [], [], []
        base = 0
        for k, ensemble in enumerate(ensembles):
            trees, width = ensemble.feature.shape
            index = base + width * np.arange(trees)[:, None] + np.arange(width)          # (trees, width) flat
            offset = base + width * np.arange(trees)[:, None]
            features.append(np.where(ensemble.leaf, 0, ensemble.feature).ravel())
            thresholds.append(ensemble.threshold.ravel())
            lefts.append(np.where(ensemble.leaf, index, offset + ensemble.left).ravel())
            rights.append(np.where(ensemble.leaf, index, offset + ensemble.right).ravel())
            values.append(ensemble.value.ravel())
            offsets.append(index[:, 0])
            owners.append(np.full(trees, k))
            base += trees * width
        self._feature, self._threshold = np.concatenate(features), np.concatenate(thresholds)
        self._left, self._right, self._value = np.concatenate(lefts), np.concatenate(rights), np.concatenate(values)
        self._roots, self._owner = np.concatenate(offsets), np.concatenate(owners)
        self._baseline = np.array([ensemble.baseline for ensemble in ensembles])
        self._depth = max(ensemble.depth for ensemble in ensembles)

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Each ensemble's prediction (E,) for one row of finite features x (F,)."""
        goes_left = x[self._feature] <= self._threshold
        node = self._roots
        for _ in range(self._depth):
            node = np.where(goes_left[node], self._left[node], self._right[node])
        return self._baseline + np.bincount(self._owner, weights=self._value[node], minlength=len(self._baseline))


def share_to_go(beyond: np.ndarray) -> np.ndarray:
    """The share of the whole path still to go, s = a / (1 + |a|), for distances beyond the hand over the path
    so far a (any shape): in (-1, 1), negative where the endpoint lies behind the hand."""
    return beyond / (1.0 + np.abs(beyond))


def beyond_over_path(share: np.ndarray) -> np.ndarray:
    """a = s / (1 - |s|), the inverse of :func:`share_to_go`, for s kept within ±``MAX_SHARE``."""
    share = np.clip(share, -MAX_SHARE, MAX_SHARE)
    return share / (1.0 - np.abs(share))


ALONG_TARGETS = {"share": beyond_over_path, "over path": lambda beyond: beyond}
"""What a people model's along regressor may predict, and how that turns into a, the distance beyond the hand
over the path so far."""


def weighted_quantile(values: np.ndarray, q, weights: np.ndarray | None = None):
    """The ``q`` quantile(s) (a float or an array in [0, 1]) of ``values`` (N,), each counting its ``weights`` (N,):
    the smallest value whose share of the weight at or below it reaches q (with equal weights, numpy's
    ``inverted_cdf`` quantile); for weights None, numpy's default (linear) quantile."""
    if weights is None:
        picked = np.quantile(values, q)
        return float(picked) if np.ndim(picked) == 0 else picked
    order = np.argsort(values, kind="stable")
    cumulative = np.cumsum(weights[order])
    at = np.searchsorted(cumulative, np.asarray(q) * cumulative[-1] * (1 - 1e-12), side="left")
    picked = values[order][np.minimum(at, len(values) - 1)]
    return float(picked) if np.ndim(picked) == 0 else picked


def _spread_regressor(X, log_squared, seed: int, weights=None):
    from sklearn.ensemble import HistGradientBoostingRegressor
    return HistGradientBoostingRegressor(max_iter=120, learning_rate=0.06, random_state=seed).fit(X, log_squared,
                                                                                                  sample_weight=weights)


def _along_regressor(X, share, seed: int, weights=None):
    from sklearn.ensemble import HistGradientBoostingRegressor
    return HistGradientBoostingRegressor(max_iter=250, learning_rate=0.06, loss="quantile", quantile=QUANTILE,
                                         random_state=seed).fit(X, share, sample_weight=weights)


def _samples(recordings):
    """Features (N, F), the endpoint's offset from the hand over L along u (N,) and across it (N,), the time
    still to go to the end over tau (N,), and the index of the recording of each sample (N,), for every sample
    from onset to end of the recordings."""
    X, along, across, remaining, owner = [], [], [], [], []
    for index, recording in enumerate(recordings):
        for k in range(2, len(recording.t) + 1):
            described = movement_features(recording.t[:k], recording.position[:k], recording.velocity[:k], recording.position[0])
            if described is None:
                continue
            features, u, path = described
            e = recording.end - recording.position[k - 1]
            on = float(e @ u)
            X.append(features)
            along.append(on / path)
            across.append(math.sqrt(max(float(e @ e) - on * on, 0.0)) / path)
            remaining.append(max(recording.end_time - recording.t[k - 1], 0.0) / features[0])
            owner.append(index)
    return np.array(X), np.array(along), np.array(across), np.array(remaining), np.array(owner)


def shipped_people_model(kind: str = "mouse") -> PeopleModel:
    """The model of ``kind`` (a key of :data:`KINDS`) fitted to recorded people that ships with comanip, read once
    per process (:data:`comanip.caching.process_caches.PROCESS_CACHES`)."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {sorted(KINDS)}, got {kind!r}")
    return PROCESS_CACHES.get(f"{kind} people model", lambda: PeopleModel.load(resources.files("comanip") / "data" /
                                                                              f"people_endpoint_{kind}.npz"))
