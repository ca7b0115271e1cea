"""Observed hand states of one reach from a file: an observations CSV (:mod:`comanip.recordings.observation_files`),
a ROS 2 bag (:mod:`comanip.recordings.ros_bags`) or a Vicon Nexus trajectories export
(:mod:`comanip.recordings.nexus_trajectories`), read the same way by ``comanip estimate --observations`` and the ROS
node's replay."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from comanip.recordings.nexus_trajectories import is_nexus_export, read_nexus_trajectories
from comanip.recordings.observation_files import read_observations
from comanip.recordings.ros_bags import bag_observations, is_bag


def read_hand_states(path: str | Path, n: int, *, check_units: bool = True, joint_angles: bool = False,
                     name: str = "observations", topic: str | None = None, frame: str | None = None,
                     marker: str | None = None, max_gap: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Times (K,) s and states (K, 2n) [q; qdot] of a reach, sorted by time, from an observations CSV, a bag or a
    Nexus export.

    A bag's or a Nexus export's hand positions (m) and their smoothed velocities (m/s) are the states of a point
    mass (q the first n axes of the hand position), timed from the movement's onset
    (:meth:`~comanip.recordings.recording.Recording.states_from_onset`); ``topic`` and ``frame`` choose a bag's
    samples, ``marker`` and ``max_gap`` an export's (:func:`~comanip.recordings.nexus_trajectories.read_nexus_trajectories`;
    None: its defaults). A CSV: :func:`~comanip.recordings.observation_files.read_observations`. ``name`` (the option
    that gave the file) begins every error's one line."""
    nexus = is_nexus_export(path)
    if (is_bag(path) or nexus) and joint_angles:
        raise ValueError(f"{name}: a {'Nexus export' if nexus else 'bag'} holds the hand's position; this model's q are "
                         f"joint angles (give a CSV of joint states, or a point-mass preset such as 'cartesian')")
    if is_bag(path):
        return bag_observations(path, n, topic, frame=frame, check_units=check_units)
    if topic is not None or frame is not None:
        raise ValueError(f"{name}: a topic and a frame choose the samples of a bag; {str(path)!r} is a CSV")
    if nexus:
        samples = read_nexus_trajectories(path, marker, max_gap=max_gap, check_units=check_units)
        return samples.recording().states_from_onset(n)
    if marker is not None or max_gap is not None:
        raise ValueError(f"{name}: a marker and a longest gap choose the samples of a Nexus export; {str(path)!r} is "
                         f"an observations CSV")
    return read_observations(path, n, check_units=check_units, joint_angles=joint_angles, name=name)
