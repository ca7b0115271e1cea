"""A simulated person whose intended hand path is a recorded person's movement, not the model's plan.

A recording (:class:`comanip.recordings.Recording`: positions p(t), m, on a screen or table (d = 2) or in a
tracker's space (d = 3)) is mapped onto the scenario's reach from the handle's start x_0 (3,) to the goal g
(3,), both m:

    x_path(t) = x_0 + (D_reach / D_rec) (u(t) e_1 + w(t) e_2 + v(t) e_3),   0 ≤ t ≤ lead + MT_rec + END_HOLD

with u(t), w(t), v(t) the recorded displacement p(t_0 + t) - p(t_0) along the recorded chord c = p_end - p(t_0),
across it horizontally (along up × c) and across it upward (along c × (up × c)), with up the recording's
upward direction (a planar recording lies flat: up = its plane's normal, v = 0); D_rec = |c|;
t_0 = onset - lead (:data:`PLAYBACK_LEAD`: the playback begins with the hand at rest shortly before the recorded
onset, so the intention leaves from rest as a person's does). On the scenario's side e_1 =
(g - x_0) / D_reach is the reach's direction (z included: the recording's progress carries the reach's height
change), e_2 = z × e_1 (normalised) the horizontal unit vector across it and e_3 = e_1 × e_2, D_reach =
|g - x_0|. So the path starts at x_0, ends at g, keeps the recording's timing, speed profile and deviations
from its chord (scaled, sideways ones horizontal, upward ones upward), and a planar recording's x–y
direction is turned onto the scenario's.

The recorded positions p(t) are first low-passed (:data:`SMOOTHING_HZ`, zero phase, the hand held where it is at
the onset before it, and at its last sample for :data:`END_HOLD` after the recording's end, which the playback
includes: 0 ≤ t ≤ lead + MT_rec + END_HOLD). A zero-phase low-pass anticipates the reach's start (by 1.5 cm/s 50 ms
before the onset of a fast reach); over the lead, the path's displacement from where it rests is faded in
(times 10 s³ - 15 s⁴ + 6 s⁵, s from 0 to 1 over the lead), so that it leaves from rest at t = 0 and is the
low-passed recording from the onset on. A pointing fingertip stops on its target by touching it, decelerating within a few tens of ms, and a
tracker adds noise; a person guiding a handle does neither, and through the feedforward M_load xddot_d below
both would become the person's force (a 16 kg handle decelerated at 5 m/s² is 80 N). The low-pass keeps the
reach itself, whose speed profile lies below about 3 Hz.

A 3-D recording's upward direction is that of the surface its reaches start and end on
(:func:`surface_normal`): the normal of the plane through the starts and ends of a set of recordings,
signed so that the hands rise off it on average (a pointing hand lifts between start and target).

The intention is that path added to where the person held the hand before the reach (the offset between
intention and the sagging hand carries over, as for the model's person), interpolated by a quintic spline that
leaves from rest and comes to rest (velocity and acceleration 0 at both ends: the holding force at t = 0 is
the person's force at rest, the reference of the force-change measures), and held at its end afterwards. The force on the
handle is the same arm impedance as :class:`comanip.simulation.person.SimulatedPerson`'s, with the same
feedforward for the load's inertia; this person does not re-plan (the recording cannot), so it never
corrects toward the goal beyond what the recording did.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.interpolate import make_interp_spline
from scipy.signal import butter, sosfiltfilt

from comanip.arguments import as_matrix, as_vector
from comanip.recordings.recording import Recording
from comanip.simulation.person import PersonParameters

PLAYBACK_LEAD = 0.05
"""Time (s, the recording's own) before the recorded onset at which the playback (the trial's t = 0) starts: the
hand rests there (the onset is where the speed last was below 2.5 % of its peak; a mouse sends no samples while
still)."""
MAX_ONSET_SPEED = 0.1
"""A recording usable as a reach starts from rest: it has PLAYBACK_LEAD of samples before its onset, and its
speed at the onset is at most this fraction of its peak."""
MAX_PATH_RATIO = 1.5
"""... its path is at most this multiple of its distance (longer ones wander, e.g. a mouse lifted and put back)."""
MIN_DISTANCE = 0.1
"""... it spans at least this distance (m), so that scaling it to a reach does not magnify its sampling noise."""
MAX_MOVEMENT_TIME = 2.0
"""... and it lasts at most this long (s)."""
SMOOTHING_HZ = 6.0
"""Cut-off (Hz, in the recording's own time) of the low-pass the recorded positions pass through before they are
played (second-order Butterworth run forward and backward: zero phase; module docstring)."""
END_HOLD = 0.15
"""Time (s, the recording's own) the recorded hand is held at its last sample after the recording's end, and played:
the low-passed path comes to rest within it (to 0.1 % of the step it smooths, at SMOOTHING_HZ, in 0.12 s)."""
RECORDING_STRIDE = 37
"""Trial seed k plays usable recording (k · stride) mod N of the development split, N usable recordings: a
stride spreads consecutive seeds over the file (whose movements come in runs by person)."""


def usable_for_reach(recording: Recording) -> bool:
    """True if the recording starts from rest, goes fairly straight, is long enough and not too slow to play
    as a reach (the thresholds above)."""
    keep = recording.t >= recording.onset - 1e-9
    speed = np.linalg.norm(recording.velocity, axis=1)
    path = float(np.sum(np.linalg.norm(np.diff(recording.position[keep], axis=0), axis=1)))
    return (recording.onset >= PLAYBACK_LEAD - 1e-9 and speed[keep][0] <= MAX_ONSET_SPEED * speed.max()
            and path <= MAX_PATH_RATIO * recording.distance
            and recording.distance >= MIN_DISTANCE and recording.movement_time <= MAX_MOVEMENT_TIME)


class RecordedReach(NamedTuple):
    """A recording mapped onto a reach."""

    t: np.ndarray
    """Times (K,), s, from the playback's start."""
    position: np.ndarray
    """Hand positions (K, 3), m, from the reach's start to its goal."""


class IntendedMotion(NamedTuple):
    """Where a recorded person's intention is along their path at one instant."""

    displacement: np.ndarray
    """From the path's start (3,), m."""
    velocity: np.ndarray
    """(3,), m/s."""
    acceleration: np.ndarray
    """(3,), m/s²."""


def recorded_reach(recording: Recording, start, goal, up=None) -> RecordedReach:
    """The recording mapped onto the reach from start (3,) m to goal (3,) m (module docstring).

    up: the recording's upward direction (3,), for a 3-D recording (:func:`surface_normal`); a planar one lies
    flat and takes none. Returns (t (K,) s from the playback's start, positions (K, 3) m): t[0] = 0 at start,
    t[-1] = PLAYBACK_LEAD + MT_rec + END_HOLD at goal (the recording's onset at PLAYBACK_LEAD), to within a sample
    step.
    """
    start, goal = as_vector("start", start, 3, "m"), as_vector("goal", goal, 3, "m")
    d = recording.position.shape[1]
    if d == 2:
        if up is not None:
            raise ValueError("a planar recording lies flat: give no up direction")
        up = np.array([0.0, 0.0, 1.0])
    elif d == 3:
        if up is None:
            raise ValueError("a 3-D recording needs its upward direction up (3,) (surface_normal)")
        up = as_vector("up", up, 3, "direction")
    else:
        raise ValueError(f"a recorded reach needs a recording (K, 2) or (K, 3), got {recording.position.shape}")
    reach = goal - start
    distance = float(np.linalg.norm(reach))
    if distance == 0:
        raise ValueError("a recorded reach needs a start away from its goal")
    times, smoothed = _low_passed(recording)
    t = times - times[0]
    recorded = np.pad(smoothed, ((0, 0), (0, 3 - d)))
    length = float(np.linalg.norm(recorded[-1] - recorded[0]))
    if length == 0:
        raise ValueError(f"recording {recording.name!r} ends where it starts")
    displacement = recorded - recorded[0]
    components = displacement @ _chord_frame(recorded[-1] - recorded[0], up).T        # (K, 3): along, across, upward
    position = start + (distance / length) * components @ _chord_frame(reach, np.array([0.0, 0.0, 1.0]))
    position[-1] = goal   # equal up to rounding
    return RecordedReach(t, position)


def _low_passed(recording: Recording) -> tuple[np.ndarray, np.ndarray]:
    """The recording's samples from its onset to its end, after :data:`PLAYBACK_LEAD` of the onset's held before and
    followed by :data:`END_HOLD` of the last one held (times (K,) s on the recording's clock), low-passed at
    :data:`SMOOTHING_HZ` and faded in from rest over the lead (positions (K, d) m; module docstring)."""
    moving = (recording.t >= recording.onset - 1e-9) & (recording.t <= recording.end_time + 1e-9)
    t, position = recording.t[moving], recording.position[moving]
    step = float(np.median(np.diff(recording.t)))
    before, after = int(np.ceil(PLAYBACK_LEAD / step - 1e-9)), int(np.ceil(END_HOLD / step - 1e-9))
    t = np.r_[t[0] - step * np.arange(before, 0, -1), t, t[-1] + step * np.arange(1, after + 1)]
    position = np.vstack([np.repeat(position[:1], before, axis=0), position, np.repeat(position[-1:], after, axis=0)])
    smoothed = sosfiltfilt(butter(2, SMOOTHING_HZ, fs=1.0 / step, output="sos"), position, axis=0)
    s = np.clip(np.arange(len(t)) / before, 0.0, 1.0)[:, None]
    return t, position[0] + (smoothed - position[0]) * (10 * s**3 - 15 * s**4 + 6 * s**5)


def _chord_frame(chord: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Rows e_1 = chord / |chord|, e_2 = up × e_1 and e_3 = e_1 × e_2, normalised (3, 3); for a chord along up,
    e_2 is the y axis projected across the chord."""
    e1 = chord / np.linalg.norm(chord)
    e2 = np.cross(up, e1)
    if np.linalg.norm(e2) < 1e-9:   # a vertical chord
        e2 = np.array([0.0, 1.0, 0.0]) - e1[1] * e1
    e2 = e2 / np.linalg.norm(e2)
    return np.array([e1, e2, np.cross(e1, e2)])


def surface_normal(recordings: list[Recording]) -> np.ndarray:
    """The upward unit direction (3,) of the surface that 3-D recordings start and end on: the normal of the
    plane fitted (least squares) to their start and end points, signed so that the hands rise off it on
    average (their displacements from their first samples point along it)."""
    if not recordings or any(r.position.shape[1] != 3 for r in recordings):
        raise ValueError("surface_normal needs 3-D recordings (K, 3)")
    ends = np.array([p for r in recordings for p in (r.position[np.searchsorted(r.t, r.onset)], r.position[-1])])
    if len(ends) < 3:
        raise ValueError("surface_normal needs the starts and ends of at least two recordings")
    normal = np.linalg.svd(ends - ends.mean(axis=0))[2][-1]
    rise = sum(float(np.mean((r.position - r.position[0]) @ normal)) for r in recordings)
    return normal if rise >= 0 else -normal


class RecordedPerson:
    """One person reaching for the goal along a recorded movement's path, holding the handle (module docstring).

    Args:
        recording: a planar or 3-D recording (:func:`usable_for_reach` says which play well).
        parameters: arm impedance; ``pace`` scales the recording's times (1: as recorded).
        start: where the handle starts (3,), m; goal: the person's goal (3,), m.
        load_inertia: M_load (3, 3), kg, for the feedforward when ``parameters.anticipates_inertia``.
        up: a 3-D recording's upward direction (3,) (:func:`recorded_reach`).
    """

    def __init__(self, recording: Recording, parameters: PersonParameters, start, goal, load_inertia=None, up=None):
        self.recording, self.parameters = recording, parameters
        self.goal = as_vector("goal", goal, 3, "m")
        t, position = recorded_reach(recording, start, goal, up)
        self.duration = float(t[-1] * parameters.pace)
        """The path's duration (s): the playback's (lead, movement time and END_HOLD) times the pace."""
        displacement = position - position[0]
        displacement[:, list(parameters.followed_axes)] = 0.0
        rest = [(1, np.zeros(3)), (2, np.zeros(3))]
        self._path = make_interp_spline(t * parameters.pace, displacement, k=5, bc_type=(rest, rest))
        self._load_inertia = np.zeros((3, 3))
        if parameters.anticipates_inertia:
            if load_inertia is None:
                raise ValueError("load_inertia (3, 3) kg is needed when the person anticipates the load's inertia")
            self._load_inertia = as_matrix("load_inertia", load_inertia, (3, 3), "kg")
        self.plans: list = []
        """Always empty: this person does not plan (the scenario's records count re-plans from it)."""
        self.replan_times: list[float] = []
        self._followed = parameters.followed()

    def intended_motion(self, t: float) -> IntendedMotion:
        """The path's displacement from its start (3,) m, its velocity (3,) m/s and acceleration (3,) m/s² at
        t (s) since the onset; at rest at the goal after the path's end."""
        if t >= self.duration:
            return IntendedMotion(self._path(self.duration), np.zeros(3), np.zeros(3))
        t = max(t, 0.0)
        return IntendedMotion(self._path(t), self._path(t, 1), self._path(t, 2))

    def start(self, intended_position, t: float = 0.0) -> None:
        """Begin the reach at time t (s), the intention at rest at intended_position (3,) m (where the person
        held the hand before the reach)."""
        self._hold = np.array(intended_position, dtype=float)
        self._clock_start = t
        self.intended_position, self.intended_velocity = self._hold.copy(), np.zeros(3)
        self._followed.start(self._hold)

    def force(self, t: float, position, velocity) -> np.ndarray:
        """Force on the handle (3,), N, with the hand at position (3,) m, velocity (3,) m/s at time t (s);
        sets the intention (``intended_position``, ``intended_velocity``) to time t."""
        displacement, self.intended_velocity, acceleration = self.intended_motion(t - self._clock_start)
        self.intended_position = self._hold + displacement
        force = self.parameters.impedance_force(self.intended_position, self.intended_velocity, position, velocity) \
            + self._load_inertia @ acceleration
        self._followed.apply(t, position, velocity, self.intended_position, self.intended_velocity, force)
        return force
