"""Observed hand states of one reach from a file: an observations CSV (:mod:`comanip.recordings.observation_files`)
or a ROS 2 bag (:mod:`comanip.recordings.ros_bags`), read the same way by ``comanip estimate --observations`` and
the ROS node's replay."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from comanip.recordings.observation_files import read_observations
from comanip.recordings.ros_bags import bag_observations, is_bag


def read_hand_states(path: str | Path, n: int, *, check_units: bool = True, joint_angles: bool = False,
                     name: str = "observations", topic: str | None = None,
                     frame: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Times (K,) s and states (K, 2n) [q; qdot] of a reach, sorted by time, from an observations CSV or a bag.

    A bag's hand positions (m) and their smoothed velocities (m/s) are the states of a point mass (q the hand
    position, n = d), timed from the movement's onset (:func:`~comanip.recordings.ros_bags.bag_observations`);
    ``topic`` and ``frame`` choose its samples. A CSV: :func:`~comanip.recordings.observation_files.read_observations`.
    ``name`` (the option that gave the file) begins every error's one line."""
    if is_bag(path):
        if joint_angles:
            raise ValueError(f"{name}: a bag holds the hand's position; this model's q are joint angles (give a CSV of "
                             f"joint states, or a point-mass preset such as 'cartesian')")
        return bag_observations(path, n, topic, frame=frame, check_units=check_units)
    if topic is not None or frame is not None:
        raise ValueError(f"{name}: a topic and a frame choose the samples of a bag; {str(path)!r} is a CSV")
    return read_observations(path, n, check_units=check_units, joint_angles=joint_angles, name=name)
