"""Measures of one co-manipulation trial that say how the robot helped the person.

All come from a :class:`~comanip.simulation.scenario.TrialRecord` (K samples, time step dt, s):

Force and work are taken from ``from_time`` on (the sync scenario: t_o, from when the robot leads; before
that every robot is passive alike), the other measures over the whole trial.

- **interaction force**: the person's force on the handle F_p (K, 3), N, as RMS and peak of ||F_p||; and the same for F_p - F_p(0), the change from the force that holds the object at rest before the
  reach (mostly its uncompensated weight, which every robot here leaves to the person alike);
- **work against the robot** (J): sum of max(0, -F_r · v) dt with F_r the impedance's force on the handle:
  the energy the robot's spring and damper take out of the handle's motion, which the person supplies;
  and the person's positive work beyond holding the object, sum of max(0, (F_p - F_p(0)) · v) dt (the
  holding force itself does negative work as the object is lowered, and would hide the rest);
- **synchronisation** between the axes the person leads (L_p) and those the robot leads (L_r): the progress
  p_L(t) = (x_L(t) - x_L(0)) · (g_L - x_L(0)) / ||g_L - x_L(0)||² of each group toward the goal, their
  RMS difference over the movement [0, MT] (dimensionless: 0.1 is 10 % of the reach), and the lag
  (s) between the times each group first passes half its way (positive: the robot's axes come later);
- **arrival in step** (the paper's synchronisation: peak speeds together, arriving together): each group's speed
  profile, ||xdot_{L_p}|| for the person's axes and ||xdot_{L_r}|| for the robot's, read as docs/formulation.md §6
  reads the handle's (:func:`comanip.analysis.speed_profile.speed_metrics`): its peak time and its movement time,
  the arrival (the speed first below 5 % of its peak after it); the person's horizontal arrival t_p, the robot's
  height arrival t_r, the arrival lag (t_r - t_p) / MT and the lag of the robot's speed peak after the person's / MT;
  and the height error ||x_{L_r}(t_p) - g_{L_r}|| (m) when the person arrives (NaN where an arrival never comes);
- **goal-estimate error** ||g_hat(t) - g|| (m) at the first estimate, at 25/50/75 % of MT, its mean over
  [first estimate, MT], and at the end of the trial;
- **completion time** (s): when the handle comes within w/2 of the goal on every axis and stays there
  (NaN if it never does); **final placement error** ||x(end) - g|| (m).

MT is docs/formulation.md §6's movement time of the handle's speed (the trial's end if it never settles).
"""

from __future__ import annotations

import numpy as np

from comanip.analysis.speed_profile import speed_metrics
from comanip.arguments import as_positive
from comanip.simulation.scenario import TrialRecord, reach_times

#: Fractions of the movement time at which the goal-estimate error is reported.
ERROR_FRACTIONS = (0.25, 0.5, 0.75)


def progress_toward(position: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Progress (K,) of positions (K, m) from their first row toward goal (m,): 0 at the start, 1 at the goal."""
    offset = goal - position[0]
    return (position - position[0]) @ offset / max(float(offset @ offset), 1e-12)


def first_passage(t: np.ndarray, values: np.ndarray, level: float) -> float:
    """The first time (s) at which values (K,) reach level, linearly interpolated; NaN if never."""
    above = np.flatnonzero(values >= level)
    if len(above) == 0:
        return float("nan")
    k = above[0]
    if k == 0:
        return float(t[0])
    return float(np.interp(level, values[k - 1 : k + 1], t[k - 1 : k + 1]))


def movement_time(record: TrialRecord) -> float:
    """docs/formulation.md §6's movement time of the handle (s), or the trial's end if its speed never settles."""
    timing = speed_metrics(record.t, np.linalg.norm(record.velocity, axis=1))
    return float(timing.movement_time) if timing.settled else float(record.t[-1])


def trial_measures(record: TrialRecord, width: float, person_axes=(0, 1), robot_axes=(2,), from_time: float = 0.0) -> dict:
    """The measures of the module docstring for one trial; width w (m) sets the completion tolerance w/2,
    from_time (s) where the force and work measures start.
    person_axes and robot_axes: indices of the axes each leads (the sync scenario's x–y and z); with
    robot_axes empty the synchronisation measures are NaN."""
    as_positive("width", width, "m")
    t, dt = record.t, float(record.t[1] - record.t[0])
    if not (np.isfinite(from_time) and t[0] <= from_time < t[-1]):
        raise ValueError(f"from_time must lie within the trial, [{t[0]}, {t[-1]}) s, got {from_time!r}")
    leading = t >= from_time - 1e-9
    force = np.linalg.norm(record.person_force[leading], axis=1)
    change = np.linalg.norm(record.person_force[leading] - record.person_force[0], axis=1)
    robot_power = np.sum(record.robot_force * record.velocity, axis=1)[leading]
    person_power = np.sum((record.person_force - record.person_force[0]) * record.velocity, axis=1)[leading]
    mt = movement_time(record)
    moving = t <= mt
    measures = {
        "rms_force_N": float(np.sqrt(np.mean(force**2))),
        "peak_force_N": float(force.max()),
        "rms_force_change_N": float(np.sqrt(np.mean(change**2))),
        "peak_force_change_N": float(change.max()),
        "work_against_robot_J": float(np.sum(np.maximum(-robot_power, 0.0)) * dt),
        "person_work_J": float(np.sum(np.maximum(person_power, 0.0)) * dt),
        "movement_time_s": mt,
    }
    person_axes, robot_axes = list(person_axes), list(robot_axes)
    if robot_axes:
        p_person = progress_toward(record.position[:, person_axes], record.goal[person_axes])
        p_robot = progress_toward(record.position[:, robot_axes], record.goal[robot_axes])
        measures["sync_error_rms"] = float(np.sqrt(np.mean((p_person - p_robot)[moving] ** 2)))
        measures["sync_lag_s"] = first_passage(t, p_robot, 0.5) - first_passage(t, p_person, 0.5)
        measures.update(arrival_measures(record, person_axes, robot_axes, mt))
    else:
        measures["sync_error_rms"] = measures["sync_lag_s"] = float("nan")
        measures.update(dict.fromkeys(ARRIVAL_KEYS, float("nan")))
    measures.update(goal_error_measures(record, mt))
    completion = reach_times(record, width / 2)
    measures["completion_time_s"] = float(np.max(completion)) if np.all(np.isfinite(completion)) else float("nan")
    measures["final_error_m"] = float(np.linalg.norm(record.position[-1] - record.goal))
    return measures


#: The keys of :func:`arrival_measures`.
ARRIVAL_KEYS = ("person_arrival_s", "robot_arrival_s", "arrival_lag_mt", "person_peak_speed_s", "robot_peak_speed_s",
                "peak_lag_mt", "height_error_at_arrival_m")


def arrival_measures(record: TrialRecord, person_axes, robot_axes, mt: float) -> dict:
    """The arrival-in-step measures of the module docstring (:data:`ARRIVAL_KEYS`) for the axes each leads (lists of
    indices), MT = mt (s): arrival and speed-peak times (s), their lags over MT (dimensionless, positive: the robot's
    axes later), the height error at the person's arrival (m)."""
    t = record.t
    person_axes, robot_axes = list(person_axes), list(robot_axes)
    person, robot = (speed_metrics(t, np.linalg.norm(record.velocity[:, axes], axis=1)) for axes in (person_axes, robot_axes))
    height_error = float("nan")
    if np.isfinite(person.movement_time):
        at = np.array([np.interp(person.movement_time, t, record.position[:, a]) for a in robot_axes])
        height_error = float(np.linalg.norm(at - record.goal[robot_axes]))
    return dict(zip(ARRIVAL_KEYS, [person.movement_time, robot.movement_time, (robot.movement_time - person.movement_time) / mt,
                                   person.t_peak, robot.t_peak, (robot.t_peak - person.t_peak) / mt, height_error]))


def speed_profiles(record: TrialRecord, grid: np.ndarray, person_axes=(0, 1), robot_axes=(2,)) -> np.ndarray:
    """The handle's speed on the person's axes, ||xdot_{L_p}||, and on the robot's, ||xdot_{L_r}|| (m/s), at the
    normalised times grid (P,) = t / MT (the paper's Fig. 7): (P, 2), NaN beyond the trial's end."""
    mt = movement_time(record)
    speeds = [np.linalg.norm(record.velocity[:, list(axes)], axis=1) for axes in (person_axes, robot_axes)]
    return np.column_stack([np.interp(grid * mt, record.t, speed, right=np.nan) for speed in speeds])


def goal_error_measures(record: TrialRecord, mt: float) -> dict:
    """Goal-estimate error (m) at the first estimate, at ERROR_FRACTIONS of mt (s), its mean from the first
    estimate to mt, and at the end; all NaN when the record holds no estimate."""
    nan = float("nan")
    names = ["goal_error_first_m"] + [f"goal_error_{int(100 * f)}pct_m" for f in ERROR_FRACTIONS] + \
            ["goal_error_mean_m", "goal_error_final_m"]
    if record.goal_estimate is None or not np.any(np.isfinite(record.goal_estimate[:, 0])):
        return dict.fromkeys(names, nan)
    error = np.linalg.norm(record.goal_estimate - record.goal, axis=1)          # NaN before the first estimate
    first = int(np.flatnonzero(np.isfinite(error))[0])
    at = [error[min(int(round(f * mt / (record.t[1] - record.t[0]))), len(error) - 1)] for f in ERROR_FRACTIONS]
    window = error[first : max(int(np.searchsorted(record.t, mt, side="right")), first + 1)]
    values = [error[first]] + [float(e) for e in at] + [float(np.mean(window)), float(error[-1])]
    return dict(zip(names, [float(v) for v in values]))
