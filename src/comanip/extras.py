"""Optional parts of comanip and the extras that install them.

``pip install comanip`` brings what planning, estimation and fitting need. The rest comes with extras:

=========  ==========================================  =====================================================
extra      brings                                      for
=========  ==========================================  =====================================================
``panda``  adam-robotics, liecasadi, example-robot-data  the Franka Panda preset and body
``sim``    MuJoCo (and the ``panda`` extra)             the co-manipulation scenarios (``comanip simulate``)
``sweeps`` Dask distributed                            sweeps and fits on several processes or a cluster
``ros``    rclpy and ROS 2 message wheels              the ROS 2 node (``comanip ros``)
``bags``   rosbags                                     reading ROS 2 bags (MCAP, sqlite3) as recordings
``data``   cursory                                     recorded mouse movements of people
``all``    every extra above
=========  ==========================================  =====================================================

A module that needs an extra imports it through :func:`require`, which raises :class:`MissingExtra` with one
line naming the extra when it is not installed; a script calls :func:`exit_without` first, which ends it with
that line instead of a traceback.
"""

from __future__ import annotations

import importlib
import importlib.util
from types import ModuleType

#: extra -> (what it is for, the top-level modules it installs; example-robot-data, data files only, is looked up
#: by :func:`comanip.bodies.panda_urdf.panda_urdf_path`)
EXTRAS = {
    "panda": ("the Franka Panda", ("adam", "liecasadi")),
    "sim": ("the co-manipulation simulation", ("mujoco",)),
    "sweeps": ("running on several processes or a cluster", ("dask", "distributed")),
    "ros": ("the ROS 2 node", ("rclpy",)),
    "bags": ("reading ROS 2 bags", ("rosbags",)),
    "data": ("the recorded movements of people", ("cursory",)),
}


class MissingExtra(ModuleNotFoundError):
    """A module of an optional extra is not installed; the message is one line naming the extra to install."""

    def __init__(self, extra: str, module: str, feature: str | None = None):
        self.extra = extra
        feature = feature or EXTRAS[extra][0]
        super().__init__(f"{feature} needs the '{extra}' extra: pip install 'comanip[{extra}]' ({module!r} is "
                         f"not installed)", name=module)

    def __str__(self) -> str:
        return self.msg


def require(module: str, extra: str, feature: str | None = None) -> ModuleType:
    """Import ``module`` and return it; :class:`MissingExtra` naming ``extra`` (one of :data:`EXTRAS`) when it, or
    a module it imports, is not installed. ``feature`` says what needs it (default: the extra's purpose)."""
    if extra not in EXTRAS:
        raise ValueError(f"extra must be one of {sorted(EXTRAS)}, got {extra!r}")
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as error:
        raise MissingExtra(extra, error.name or module, feature) from None


def missing(extra: str) -> MissingExtra | None:
    """The :class:`MissingExtra` that using ``extra`` would raise, or None when its modules are installed (found,
    not imported)."""
    if extra not in EXTRAS:
        raise ValueError(f"extra must be one of {sorted(EXTRAS)}, got {extra!r}")
    absent = [module for module in EXTRAS[extra][1] if importlib.util.find_spec(module) is None]
    return MissingExtra(extra, absent[0]) if absent else None


def exit_without(*extras: str) -> None:
    """For scripts: end the program with the one-line hint of the first of ``extras`` that is not installed."""
    for extra in extras:
        error = missing(extra)
        if error is not None:
            raise SystemExit(str(error))
