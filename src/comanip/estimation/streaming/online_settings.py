"""One description of online goal estimation, from which every front end builds its estimator and its loop.

:class:`OnlineSettings` says everything that makes an online estimator and the loop that feeds it: the reaching
model (a preset name or a model YAML), the goal width, the prior's spread, the estimator's
:class:`~comanip.estimation.online.online_options.OnlineOptions` (whom it expects, the forecast's horizon, ...),
the loop's :class:`~comanip.estimation.streaming.estimation_loop.LoopSettings` (rate, segmentation, ...), the leads
at which a front end reads the forecast ahead, and whether the person is learned from reach to reach.
:meth:`OnlineSettings.estimator` and :meth:`OnlineSettings.estimation_loop` are the one place an online estimator
is built; the ROS 2 node, the simulated robots, the handover's release, the demo, ``comanip estimate --online`` and
:class:`~comanip.estimation.streaming.reach_stream.ReachStream` all build theirs there.

Named descriptions ship as YAML beside this module (``estimators/*.yaml``, :func:`names`): ``recorded``, a
person who may not move as the model does (the default); ``correcting``, the model's own reach with deviations
corrected (the simulated person); ``sync_robot``, the sync robot's belief (a person who corrects, the height led by
the robot, the goal covariance calibrated). :func:`load` reads one by name or any file of the same shape::

    model: cartesian          # a preset name or a model YAML
    width: null               # m; null: the model's
    prior_std: null           # m: a number, one per axis, "width", or null (the weak default)
    options: {timing: estimated, forecast_horizon: 0.5}     # OnlineOptions fields
    loop: {rate: 100.0, segmentation: {radius: 0.01}}       # LoopSettings fields
    forecast_leads: [0.1, 0.2, 0.3]                         # s
    learn_person: true
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np
import yaml

from comanip import presets
from comanip.arguments import as_goal_width
from comanip.estimation.calibration.goal_smoothing import GoalSmoothing
from comanip.estimation.calibration.person_calibration import CalibrationSettings, PersonCalibration
from comanip.estimation.goal_prior import prior_covariance
from comanip.estimation.model_reaches.model_families import FamilyCache
from comanip.estimation.online.online_estimator import OnlineGoalEstimator
from comanip.estimation.online.online_options import OnlineOptions
from comanip.estimation.streaming.estimation_loop import EstimationLoop, LoopSettings
from comanip.estimation.streaming.reach_segmentation import SegmentationSettings
from comanip.model import ReachingModel
from comanip.planning.planner import Planner

ESTIMATOR_DIR = Path(__file__).parent / "estimators"
"""Where the named descriptions are kept (one YAML file each)."""


@dataclass(frozen=True)
class OnlineSettings:
    """An online estimator and its loop, described (module docstring). Units: m, s, Hz."""

    model: str = "cartesian"
    """The reaching model: a built-in preset name or a model YAML path (:func:`comanip.presets.load`); a point
    mass, whose position is the hand's."""
    width: float | None = None
    """Goal width w (m); None: the model's."""
    prior_std: float | tuple[float, ...] | str | None = None
    """The prior goal's standard deviation (m): a number, one per axis, ``"width"`` (the paper's W), or None (the
    weak default, 10 m); :mod:`comanip.estimation.goal_prior`."""
    options: OnlineOptions = field(default_factory=OnlineOptions)
    """How the estimator works (:class:`~comanip.estimation.online.online_options.OnlineOptions`)."""
    loop: LoopSettings = field(default_factory=LoopSettings)
    """How the loop pairs, segments and paces a stream (:class:`~comanip.estimation.streaming.estimation_loop.LoopSettings`)."""
    forecast_leads: tuple[float, ...] = (0.1, 0.2, 0.3)
    """How far ahead (s) a front end reads the forecast of the hand (``comanip estimate --online``'s columns)."""
    learn_person: bool = True
    """Learn the person's amplitude, pace and spread from each finished reach
    (:mod:`comanip.estimation.calibration.person_calibration`); False: every reach is a person not seen yet."""

    def __post_init__(self):
        if not isinstance(self.model, str) or not self.model.strip():
            raise ValueError(f"model must be a preset name or a model YAML path, got {self.model!r}")
        model = self.reaching_model()
        if self.width is not None:
            object.__setattr__(self, "width", as_goal_width("width", self.width))
        if isinstance(self.prior_std, (list, tuple, np.ndarray)):
            object.__setattr__(self, "prior_std", tuple(float(v) for v in self.prior_std))
        prior_covariance(self._prior_std(), model, self.width or model.width)
        if not isinstance(self.options, OnlineOptions):
            raise ValueError(f"options must be an OnlineOptions, got {type(self.options).__name__}")
        if not isinstance(self.loop, LoopSettings):
            raise ValueError(f"loop must be a LoopSettings, got {type(self.loop).__name__}")
        leads = tuple(float(v) for v in np.atleast_1d(np.asarray(self.forecast_leads, dtype=float)))
        if not leads or not all(math.isfinite(v) and v > 0 for v in leads):
            raise ValueError(f"forecast_leads must be times ahead > 0 s, got {self.forecast_leads!r}")
        object.__setattr__(self, "forecast_leads", leads)
        if not isinstance(self.learn_person, bool):
            raise ValueError(f"learn_person must be true or false, got {self.learn_person!r}")

    def reaching_model(self) -> ReachingModel:
        """The model :attr:`model` names; a ValueError names the setting."""
        try:
            return presets.load(self.model)
        except ValueError as error:
            raise ValueError(f"model: {error}") from None

    def replace(self, **changes) -> "OnlineSettings":
        """These settings with ``changes`` (field names), checked again."""
        return dataclasses.replace(self, **changes)

    def person(self) -> PersonCalibration:
        """A person not seen yet, learned from reach to reach as :attr:`learn_person` says (pass it to several
        estimators to share it)."""
        return PersonCalibration(CalibrationSettings(learns=self.learn_person))

    def estimator(self, start=None, *, prior_goal=None, model: ReachingModel | Planner | None = None,
                  cache: FamilyCache | None = None, person: PersonCalibration | None = None) -> OnlineGoalEstimator:
        """The online estimator these settings describe, the one place one is built.

        Args:
            start: the reach's start at rest (nx,) or (2n,); None: at rest at the origin (a loop resets it for
                every reach).
            prior_goal: g_bar (d,) m; None: the start's hand position.
            model: a ReachingModel or Planner to use instead of loading :attr:`model` (a front end that has built
                one already: a compiled planner, a scenario's model).
            cache: where the reach family is kept (:class:`~comanip.estimation.model_reaches.model_families.FamilyCache`;
                None: the process's).
            person: what is known of the person (None: :meth:`person`, a person not seen yet).
        """
        model = self.reaching_model() if model is None else model
        state_size = (model.model if isinstance(model, Planner) else model).state_size
        start = np.zeros(state_size) if start is None else start
        return OnlineGoalEstimator(model, start, prior_goal=prior_goal, prior_std=self._prior_std(), width=self.width,
                                   options=self.options, cache=cache, person=self.person() if person is None else person)

    def estimation_loop(self, start=None, *, prior_goal=None, model: ReachingModel | Planner | None = None,
                        cache: FamilyCache | None = None, person: PersonCalibration | None = None) -> EstimationLoop:
        """The loop of :attr:`loop` around :meth:`estimator` (the same arguments)."""
        return EstimationLoop(self.estimator(start, prior_goal=prior_goal, model=model, cache=cache, person=person), self.loop)

    def _prior_std(self):
        return np.array(self.prior_std) if isinstance(self.prior_std, tuple) else self.prior_std

    # ---- as YAML
    @classmethod
    def from_mapping(cls, values: dict) -> "OnlineSettings":
        """Settings from a mapping such as :meth:`to_mapping` gives (``options`` and ``loop`` as mappings of their
        fields); an unknown name is a ValueError listing the known ones."""
        values = dict(_checked_mapping("online settings", values, cls))
        if "options" in values:
            options = dict(_checked_mapping("options", values["options"], OnlineOptions, exclude=("people_model",)))
            if isinstance(options.get("goal_smoothing"), dict):
                options["goal_smoothing"] = GoalSmoothing(**_checked_mapping("options.goal_smoothing", options["goal_smoothing"],
                                                                             GoalSmoothing))
            values["options"] = OnlineOptions(**_tuples(options))
        if "loop" in values:
            loop = dict(_checked_mapping("loop", values["loop"], LoopSettings))
            if loop.get("segmentation") is not None:
                loop["segmentation"] = SegmentationSettings(**_checked_mapping("loop.segmentation", loop["segmentation"],
                                                                               SegmentationSettings))
            if loop.get("horizon") is None:
                loop.pop("horizon", None)
            values["loop"] = LoopSettings(**loop)
        return cls(**_tuples(values))

    def to_mapping(self) -> dict:
        """The settings as plain values (nested mappings, lists), as a YAML file holds them."""
        options = {f.name: getattr(self.options, f.name) for f in fields(OnlineOptions) if f.name != "people_model"}
        smoothing = options["goal_smoothing"]
        options["goal_smoothing"] = None if smoothing is None else dataclasses.asdict(smoothing)
        loop = {f.name: getattr(self.loop, f.name) for f in fields(LoopSettings)}
        loop["segmentation"] = None if self.loop.segmentation is None else dataclasses.asdict(self.loop.segmentation)
        loop["horizon"] = None if math.isinf(loop["horizon"]) else loop["horizon"]
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out.update(options=options, loop=loop)
        return _lists(out)

    def save(self, path: str | Path) -> Path:
        """Write the settings as YAML (readable by :func:`load`)."""
        path = Path(path)
        path.write_text(yaml.safe_dump(self.to_mapping(), sort_keys=False))
        return path


def names() -> list[str]:
    """The names of the shipped descriptions."""
    return sorted(p.stem for p in ESTIMATOR_DIR.glob("*.yaml"))


def load(name_or_path: str | Path) -> OnlineSettings:
    """A shipped description by name (:func:`names`) or one from a YAML file (an OnlineSettings is returned as it
    is); a one-line ValueError for an unknown name, an unreadable or invalid file, and unknown or bad settings."""
    if isinstance(name_or_path, OnlineSettings):
        return name_or_path
    if isinstance(name_or_path, str) and name_or_path in names():
        path = ESTIMATOR_DIR / f"{name_or_path}.yaml"
    else:
        path = Path(name_or_path)
        if path.suffix not in (".yaml", ".yml") or not path.is_file():
            raise ValueError(f"an online estimator must be one of {names()} or an existing .yaml file, got {str(name_or_path)!r}")
    try:
        values = yaml.safe_load(path.read_text())
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as error:
        raise ValueError(f"{str(path)!r} is not a readable YAML file: {str(error).splitlines()[0]}") from None
    return OnlineSettings.from_mapping(values or {})


def _checked_mapping(name: str, values, kind, exclude: tuple[str, ...] = ()) -> dict:
    """``values`` if it is a mapping of field names of the dataclass ``kind`` (but ``exclude``), else a ValueError."""
    if not isinstance(values, dict):
        raise ValueError(f"{name} must be a mapping of setting names to values, got a {type(values).__name__}")
    known = [f.name for f in fields(kind) if f.name not in exclude]
    unknown = sorted(set(values) - set(known))
    if unknown:
        raise ValueError(f"unknown {name} setting(s) {unknown}; the known ones are {known}")
    return values


def _tuples(values: dict) -> dict:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()}


def _lists(value):
    if isinstance(value, dict):
        return {k: _lists(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [_lists(v) for v in value]
    return value
