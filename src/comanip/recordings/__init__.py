"""Recorded human movements: a typed :class:`Recording`, its preprocessing and loaders (CSV, ROS 2 bags,
``cursory``, motion capture: tracker CSVs, TAT-HUM, Vicon Nexus)."""

from comanip.recordings.csv_recordings import load_csv_recordings
from comanip.recordings.cursory_data import load_cursory
from comanip.recordings.motion_capture import TrackedSamples, load_tathum, read_tracker_csv
from comanip.recordings.nexus_trajectories import load_nexus_trajectories, read_nexus_trajectories
from comanip.recordings.preprocessing import recording_from_samples
from comanip.recordings.recording import Recording
from comanip.recordings.ros_bags import read_bag

__all__ = ["Recording", "TrackedSamples", "load_csv_recordings", "load_cursory", "load_nexus_trajectories", "load_tathum",
           "read_bag", "read_nexus_trajectories", "read_tracker_csv", "recording_from_samples"]
