"""The simulated people a scenario can meet, by name: what ``comanip simulate sync --person`` and the demo choose.

A name is one of

- ``model``: the reaching model's own person (:class:`~comanip.simulation.person.SimulatedPerson`: the
  Cartesian preset with motor noise, re-planning from the hand they see);
- ``recorded``: a person whose intended hand path is a recorded mouse movement (the development split of the
  ``cursory`` data, the ``data`` extra), scaled and turned onto the reach
  (:class:`~comanip.simulation.recorded_person.RecordedPerson`);
- ``arm``: the same with a motion-capture arm reach in 3-D, one of the ten shipped in
  ``examples/data/arm_reaches/`` (:data:`SHIPPED_ARM_REACHES`);
- a folder of the user's own arm reaches, played as ``arm`` plays the shipped ones (:func:`arm_reach_layout`): in
  the TAT-HUM layout (:func:`comanip.recordings.load_tathum`: ``trajectory_data/`` and ``trial_data/`` inside), or
  Vicon Nexus trajectories exports (:func:`comanip.recordings.load_nexus_trajectories`, the fingertip of the arm
  that reached), one person's folder (``ue_adl/ADL003``: that person alone) or a folder of people's (one
  sub-folder each);

optionally followed by ``-xP``, P > 0 the person's pace: their whole movement takes P times as long
(:attr:`PersonParameters.pace`; ``arm-x2.5``: the arm reach played 2.5 times slower, ``model-x0.7``: the model's
person 30 % faster). Trial seed k picks the person's motor noise (``model``) or their recording (the others:
:meth:`comanip.simulation.ScenarioSetup.recording`).

>>> person = choose_person("arm-x2.5")
>>> setup = ScenarioSetup(SyncSettings(person=person.parameters), arm_reaches=person.arm_reaches)
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from comanip.simulation.person import PersonParameters

SHIPPED_ARM_REACHES = Path(__file__).resolve().parents[3] / "examples" / "data" / "arm_reaches" / "tathum" / "data_3d"
"""The arm reaches the ``arm`` person plays: ten recorded reaches in the TAT-HUM layout, in a clone of comanip's
source (``examples/data/arm_reaches/tathum/SOURCE.md``); an installed package without the source has none."""

#: person name -> where their intended hand path comes from (:attr:`PersonParameters.hand_path`)
PERSON_NAMES = {"model": "model", "recorded": "recorded", "arm": "recorded-arm"}

_PACED = re.compile(r"^(?P<name>.+)-x(?P<pace>[0-9]*\.?[0-9]+)$")

USAGE = ("model, recorded, arm or a folder of arm reaches (TAT-HUM layout, or Vicon Nexus exports: one person's "
         "folder such as ue_adl/ADL003, or a folder of people's), each optionally with -xP, P > 0 its pace "
         "(arm-x2.5: 2.5 times slower)")
"""What a person's name may be, for error messages and help texts."""


@dataclass(frozen=True)
class ChosenPerson:
    """A person chosen by name: their parameters and, for an arm person, the folder their reaches come from."""

    name: str
    """The name as given (e.g. ``"arm-x2.5"``)."""
    parameters: PersonParameters
    """Where their intended hand path comes from and their pace; the arm impedance is the default's."""
    arm_reaches: Path | None
    """The folder of an arm person's reaches (the setup's ``arm_reaches``; :func:`arm_reach_layout`); None for the
    others."""


def choose_person(name: str) -> ChosenPerson:
    """The person of that name (module docstring); a one-line ValueError naming what is allowed otherwise, before
    any recording is read (a missing ``data`` extra for ``recorded`` is that extra's one-line error)."""
    if not isinstance(name, str) or not name.strip():
        raise ValueError(f"the person must be {USAGE}; got {name!r}")
    base, pace = name, 1.0
    match = _PACED.match(name)
    if match and not Path(name).is_dir():       # a folder whose own name ends in -xP is that folder
        base, pace = match["name"], float(match["pace"])
        if not (math.isfinite(pace) and pace > 0):
            raise ValueError(f"the person's pace P in {name!r} must be a number > 0 ({USAGE})")
    if base in PERSON_NAMES:
        if base == "recorded":
            from comanip.extras import missing

            if (absent := missing("data")) is not None:
                raise absent
        folder = shipped_arm_reaches() if base == "arm" else None
        return ChosenPerson(name, PersonParameters(hand_path=PERSON_NAMES[base], pace=pace), folder)
    folder = Path(base)
    if not folder.is_dir():
        raise ValueError(f"the person must be {USAGE}; {base!r} is neither a name nor a folder")
    arm_reach_layout(folder)
    return ChosenPerson(name, PersonParameters(hand_path="recorded-arm", pace=pace), folder)


def arm_reach_layout(folder: str | Path) -> str:
    """How a folder of arm reaches is laid out: ``"tathum"`` (``trajectory_data/`` and ``trial_data/`` inside) or
    ``"nexus"`` (Vicon Nexus trajectories exports in it, or in one sub-folder per person); a one-line ValueError
    saying what a folder needs otherwise. Reads no more than the first line of the CSV files in it (and in its
    sub-folders)."""
    from comanip.recordings.nexus_trajectories import nexus_exports

    folder = Path(folder)
    if (folder / "trajectory_data").is_dir() and (folder / "trial_data").is_dir():
        return "tathum"
    if nexus_exports(folder):
        return "nexus"
    raise ValueError(f"the arm reaches' folder {str(folder)!r} is neither in the TAT-HUM layout (trajectory_data/ and "
                     f"trial_data/ inside) nor holds Vicon Nexus trajectories exports (in it or in one sub-folder per "
                     f"person; docs/data_formats.md)")


def shipped_arm_reaches() -> Path:
    """:data:`SHIPPED_ARM_REACHES`, or a one-line ValueError saying where they are when this installation lacks them."""
    if not SHIPPED_ARM_REACHES.is_dir():
        raise ValueError(f"the shipped arm reaches are in examples/data/arm_reaches/ of comanip's source, not beside "
                         f"this installation ({SHIPPED_ARM_REACHES} is missing): install from a clone "
                         f"(pip install -e .) or name a folder of arm reaches in the TAT-HUM layout")
    return SHIPPED_ARM_REACHES
