"""The forecast of a reach under way: the reaching model's continuation from the hand's state now.

A robot moving with a person follows where their hand will be, not only where it stops. At an update at time
t_now (s) the hand is at x (d,) m moving at v (d,) m/s, heading for the estimated goal g (d,) m, where it stops
at t_stop (s, the estimate's timing). The forecast is the model's own reach, continued from the hand:

1. **The phase.** The model's reach from rest to the distance D = |g - x_0| (a member of the
   :class:`~comanip.estimation.model_reaches.reach_family.ReachFamily`, along its axis a(tau) m, a'(tau) m/s, moving from
   tau_on to tau_end) is at phase tau when the hand is: the dimensionless ratio

       phi(tau) = a'(tau) (tau_end - tau) / (D - a(tau))

   (speed times time to go over distance to go) equals the hand's, |v_g| (t_stop - t_now) / |g - x|, v_g the
   hand's velocity towards g. phi rises from 0 at the onset to its largest value near the end; a hand outside
   that range is read at the nearest end.
2. **The continuation.** From its phase on, the model's reach is its optimal continuation from the state it is
   in (a plan from rest, by the principle of optimality, goes on as planned). It is turned onto the line from
   x to g, scaled to the distance left, r = |g - x|, and played at the pace p = (t_stop - t_now) / (tau_end - tau):

       x(t) = x + u (a(tau + s) - a(tau)) r / (a(tau_end) - a(tau)),   s = (t - t_now) / p,

   so it starts at the hand, arrives at g at t_stop (and stays) and leaves with the hand's speed towards g. Every state block
   (velocity, activation forces) is scaled as :mod:`~comanip.estimation.model_reaches.reach_timing` plays a plan at a pace.
3. **The rest of the hand's velocity** (across the line, or along it where the phase was read at an end), dv,
   is carried by a term dv sigma (1 - sigma / R)², sigma = t - t_now, R = t_stop - t_now: it leaves with dv and
   is gone, at rest, by t_stop. So the forecast's velocity at t_now is the hand's. Given the hand's acceleration,
   the rest of it, da, is carried likewise by da sigma² (1 - sigma / R)³ / 2 (the state's force blocks stay the
   model's).
4. **Its covariance** is the model's belief of the rest of the reach given the state now (the motor noise still to
   come: Sigma_j - A^(j-k) Sigma_k A^(j-k)^T from the model's closed-form belief Sigma_j, turned and scaled like
   the mean), plus the goal's uncertainty carried in proportion to the distance covered,
   ((x(t) - x) · u / r)² P_g.

Shapes: d task dimensions (= n, a point mass), nx = blocks · n state entries, M query times.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from comanip.estimation.model_reaches.reach_family import FamilyMember, ReachFamily
from comanip.estimation.model_reaches.reach_timing import movement_span

LAST_SHARE = 0.05
"""The phase is read where at least this share of the model's reach is still to go."""
SHORTEST_REMAINING_S = 0.02
"""Time to the stop (s) a forecast gives at least: a hand seen after its estimated stop still has to stop."""


class ForecastPoint(NamedTuple):
    """The forecast at M times."""

    t: np.ndarray
    """Times (M,), s, on the estimator's clock."""
    position: np.ndarray
    """Mean hand positions (M, d), m."""
    velocity: np.ndarray
    """Mean hand velocities (M, d), m/s."""
    covariance: np.ndarray
    """Hand position covariances (M, d, d), m²."""


@dataclass(frozen=True)
class HandForecast:
    """The forecast of the rest of a reach from the hand's state at ``t[0]`` (module docstring), on a grid of
    K + 1 times; :meth:`at` reads it at any time.

    Shapes: K + 1 grid times, nx state entries, d = n task dimensions."""

    t: np.ndarray
    """Grid times (K+1,), s, from the update's time t_now to the stop t_stop."""
    mean: np.ndarray
    """Mean states [x; v; activation forces] (K+1, nx) in m, m/s, N."""
    cov: np.ndarray
    """State covariances (K+1, nx, nx), the goal's uncertainty included in the position block."""
    stop_time: float
    """t_stop (s): when the forecast hand arrives (its speed falls below 5 % of its peak for good)."""
    pace: float
    """p: forecast time per model time (> 1 slower than the model's reach)."""
    phase: float
    """tau (s of model time): where in the model's reach the hand is."""

    d: int
    """Task dimensions d (the first block of the state is the hand's position)."""
    continuation: np.ndarray
    """The model's continuation alone (steps 1–2 of the module docstring) at the grid times: positions and the
    slopes of the cubic Hermite curve through them, (K+1, 2d) m and m/s, each slope that of the chord across its
    neighbours (:func:`_chord_slopes`; the model's Euler step moves x_i with v_i over a whole step, so no smooth curve honours the grid
    velocities too; step 3 makes the forecast's velocity the hand's)."""
    velocity_rest: np.ndarray
    """dv (d,), m/s: the hand's velocity beyond the continuation's (step 3)."""
    acceleration_rest: np.ndarray
    """da (d,), m/s²: the hand's acceleration beyond the continuation's and dv's term (step 3)."""

    @property
    def position(self) -> np.ndarray:
        """Mean hand positions (K+1, d), m."""
        return self.mean[:, :self.d]

    @property
    def velocity(self) -> np.ndarray:
        """Mean hand velocities (K+1, d), m/s."""
        return self.mean[:, self.d:2 * self.d]

    def at(self, times) -> ForecastPoint:
        """The forecast at ``times`` (M,) s (a number: M = 1): the continuation's Hermite curve, the rest of the
        hand's velocity and acceleration in closed form, the covariance linearly between grid times. Before t_now it
        is the hand now; after the stop, at rest on it."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if times.ndim != 1 or not np.all(np.isfinite(times)):
            raise ValueError(f"times must be finite times in s, a number or a 1-D array; got shape {times.shape}")
        d, t = self.d, self.t
        clipped = np.clip(times, t[0], t[-1])
        k = np.clip(np.searchsorted(t, clipped, side="right") - 1, 0, len(t) - 2)
        position, velocity = _hermite(t, self.continuation[:, :d], self.continuation[:, d:], clipped, k)
        s = ((clipped - t[k]) / (t[k + 1] - t[k]))[:, None]
        velocity[times >= t[-1]] = 0.0
        rest_position, rest_velocity = _rest_terms(clipped - t[0], t[-1] - t[0], self.velocity_rest, self.acceleration_rest)
        weight = s[:, :, None]
        covariance = (1 - weight) * self.cov[k, :d, :d] + weight * self.cov[k + 1, :d, :d]
        return ForecastPoint(times, position + rest_position, velocity + rest_velocity, covariance)


def within_horizon(forecast: HandForecast, horizon: float | None) -> ForecastPoint:
    """The forecast's grid up to ``horizon`` s after its first time, its last point there (between grid points,
    linearly between them; None: the whole grid): times (K+1,) s, the hand's mean positions (K+1, d) m and
    velocities (K+1, d) m/s and position covariances (K+1, d, d) m²."""
    t, mean, cov, d = forecast.t, forecast.mean, forecast.cov, forecast.d
    if horizon is not None and t[0] + horizon < t[-1]:
        end = t[0] + horizon
        k = int(np.searchsorted(t, end, side="right"))     # t[k - 1] <= end < t[k]
        weight = (end - t[k - 1]) / (t[k] - t[k - 1])
        if weight <= 1e-12:
            t, mean, cov = t[:k], mean[:k], cov[:k]
        else:
            t = np.r_[t[:k], end]
            mean = np.vstack([mean[:k], (1 - weight) * mean[k - 1] + weight * mean[k]])
            cov = np.concatenate([cov[:k], ((1 - weight) * cov[k - 1] + weight * cov[k])[None]])
    return ForecastPoint(t, mean[:, :d], mean[:, d:2 * d], cov[:, :d, :d])


def _hermite(t: np.ndarray, x: np.ndarray, m: np.ndarray, times: np.ndarray, k: np.ndarray):
    """Position and velocity (M, d) at ``times`` (M,) s, in intervals ``k`` (M,), of the cubic Hermite curve through
    positions x (K+1, d) m with slopes m (K+1, d) m/s at times t (K+1,) s."""
    dt = (t[k + 1] - t[k])[:, None]
    s = (times[:, None] - t[k, None]) / dt
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    position = h00 * x[k] + h10 * dt * m[k] + h01 * x[k + 1] + h11 * dt * m[k + 1]
    d00, d10, d01, d11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, -6 * s**2 + 6 * s, 3 * s**2 - 2 * s
    velocity = (d00 * x[k] + d01 * x[k + 1]) / dt + d10 * m[k] + d11 * m[k + 1]
    return position, velocity


def _chord_slopes(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Slopes (K+1, d) of positions x (K+1, d) at times t (K+1,): the chord across the neighbours; at each end,
    the slope of the parabola through the end interval with its inner slope (so the end interval bends as its
    neighbour does). Two points: the chord."""
    chord = (x[1:] - x[:-1]) / (t[1:] - t[:-1])[:, None]
    if len(t) == 2:
        return np.vstack([chord, chord])
    slopes = np.empty_like(x)
    slopes[1:-1] = (x[2:] - x[:-2]) / (t[2:] - t[:-2])[:, None]
    slopes[0] = 2 * chord[0] - slopes[1]
    slopes[-1] = 2 * chord[-1] - slopes[-2]
    return slopes


def _rest_terms(sigma: np.ndarray, remaining: float, dv: np.ndarray, da: np.ndarray):
    """Position and velocity (M, d) of step 3's terms at times sigma (M,) s after t_now, R = ``remaining`` s."""
    sigma = np.minimum(sigma, remaining)[:, None]
    left = 1 - sigma / remaining
    position = sigma * left**2 * dv + 0.5 * sigma**2 * left**3 * da
    velocity = left * (1 - 3 * sigma / remaining) * dv + sigma * left**2 * (1 - 2.5 * sigma / remaining) * da
    return position, velocity


def continued_reach(family: ReachFamily, reach_start: np.ndarray, t_now: float,
                    position: np.ndarray, velocity: np.ndarray, goal: np.ndarray, goal_covariance: np.ndarray,
                    stop_time: float | None, acceleration: np.ndarray | None = None,
                    member: FamilyMember | None = None) -> HandForecast:
    """The forecast (module docstring) of the hand at ``position`` (d,) m and ``velocity`` (d,) m/s at ``t_now``
    (s), heading for ``goal`` (d,) m with covariance ``goal_covariance`` (d, d) m², in a reach that started at
    rest at ``reach_start`` (d,) m and stops at ``stop_time`` (s; None: where the model's own reach from t = 0
    does), accelerating at ``acceleration`` (d,) m/s² now (None, or an entry NaN: as the model's reach does at
    its phase). ``member``: the family's member at the goal's distance where the caller has read it already
    (:attr:`~comanip.estimation.model_reaches.reach_family.ReachPrediction.member`), else it is read here."""
    model = family.model
    n, H, h = family.n, family.H, model.h
    to_goal = goal - position
    r = float(np.linalg.norm(to_goal))
    D = float(np.linalg.norm(goal - reach_start))
    distance = family.in_range(max(D, r, 1e-9))
    if member is None or member.distance != distance:
        member = family.member(distance)
    along = member.along                                              # (H+1, blocks) in the member's frame
    a, speed = along[:, 0], along[:, 1]
    first, last = movement_span(np.abs(speed)) if np.abs(speed).max() > 0 else (0, H)
    tau = h * np.arange(H + 1)
    end = tau[last]
    if stop_time is None:
        stop_time = end
    remaining = max(stop_time - t_now, SHORTEST_REMAINING_S)
    u = to_goal / r if r > 0 else (velocity / np.linalg.norm(velocity) if np.linalg.norm(velocity) > 0 else np.eye(n)[0])
    towards = float(velocity @ u)

    # 1. the phase: phi(tau) over the moving part, read where it equals the hand's
    # phases with at least LAST_SHARE of the reach still to go: nearer the end the distance left is too small to
    # scale onto the hand's (the rest of its velocity goes to step 3)
    usable = first + max(int(np.count_nonzero(a[last] - a[first:last] >= LAST_SHARE * (a[last] - a[first]))), 1)
    left = max(D, r) - a[first:usable]
    phi = speed[first:usable] * (end - tau[first:usable]) / np.maximum(left, 1e-12)
    phase = _phase(tau[first:usable], phi, towards * remaining / max(r, 1e-12), end - remaining)
    pace = remaining / max(end - phase, h)

    # 2. the continuation: the member from its phase on, on the model's grid, turned, scaled and played at p
    steps = tau[(tau > phase + 0.25 * h) & (tau <= end)]           # no sliver of a first step
    model_times = np.concatenate(([phase], steps))
    t = t_now + pace * (model_times - phase)
    mean, block_scale = _turned_tail(along, tau, model_times, (first, last), r, pace, u, position)

    # 3. the rest of the velocity and acceleration, gone by the stop
    if len(t) == 1:                          # a hand at or past the stop: the continuation holds still
        t, mean = np.array([t[0], t[0] + remaining]), np.vstack([mean, mean])
        mean[1, n:] = 0.0
    continuation, dv, da = _add_rest(t, mean, n, t_now, remaining, velocity, acceleration)

    # 4. the covariance: the motor noise still to come, and the goal's uncertainty along the way
    covered = np.clip(((mean[:, :n] - position) @ u) / max(r, 1e-12), 0.0, None)
    cov = _forecast_covariance(family, member, phase, model_times, len(t), np.repeat(block_scale, n), u)
    cov[:, :n, :n] += covered[:, None, None] ** 2 * goal_covariance
    arrival = t_now + pace * (end - phase)
    return HandForecast(t=t, mean=mean, cov=cov, stop_time=float(arrival), pace=float(pace), phase=float(phase), d=n,
                        continuation=continuation, velocity_rest=dv, acceleration_rest=da)


def _turned_tail(along: np.ndarray, tau: np.ndarray, model_times: np.ndarray, span: tuple[int, int], r: float,
                 pace: float, u: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Step 2 of the module docstring: the member's states along its axis ``along`` (H+1, blocks) at grid times
    ``tau`` (H+1,) s, read at ``model_times`` (K+1,) s, from the hand at ``position`` (d,) m, scaled to the distance
    left ``r`` (m; the member moving over the steps ``span``), played at ``pace`` and turned onto ``u`` (d,). Returns
    the mean states (K+1, blocks·d) and each block's scale (blocks,)."""
    blocks, n = along.shape[1], u.size
    first, last = span
    a = along[:, 0]
    tail = np.array([np.interp(model_times, tau, along[:, b]) for b in range(blocks)]).T     # (K+1, blocks)
    left_now = max(a[last] - tail[0, 0], LAST_SHARE * (a[last] - a[first]), 1e-12)
    block_scale = r / left_now * np.array([1.0, 1.0 / pace] + [pace ** -2] * (blocks - 2))
    shifted = tail.copy()
    shifted[:, 0] -= tail[0, 0]
    shifted *= block_scale
    mean = (shifted[:, :, None] * u).reshape(len(model_times), blocks * n)
    mean[:, :n] += position
    return mean, block_scale


def _add_rest(t: np.ndarray, mean: np.ndarray, n: int, t_now: float, remaining: float, velocity: np.ndarray,
              acceleration: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 3 of the module docstring on the continuation's mean states (K+1, nx) at times ``t`` (K+1,) s, in place:
    its velocities become the chord slopes plus the rest of the hand's ``velocity`` (d,) m/s and ``acceleration``
    (d,) m/s² (None: none), gone by ``remaining`` s after ``t_now``. Returns the continuation alone (positions and
    slopes, (K+1, 2d)), dv (d,) m/s and da (d,) m/s²."""
    slopes = _chord_slopes(t, mean[:, :n])
    continuation = np.hstack([mean[:, :n], slopes])
    dv = velocity - slopes[0]
    dt = t[1] - t[0]                          # the continuation's acceleration now, on its Hermite curve
    start_acceleration = 6 * (mean[1, :n] - mean[0, :n]) / dt**2 - (4 * slopes[0] + 2 * slopes[1]) / dt
    da = np.zeros(n) if acceleration is None else np.nan_to_num(acceleration - (start_acceleration - 4 * dv / remaining))
    rest_position, rest_velocity = _rest_terms(t - t_now, remaining, dv, da)
    mean[:, n:2 * n] = slopes + rest_velocity
    mean[:, :n] += rest_position
    return continuation, dv, da


def _forecast_covariance(family: ReachFamily, member: FamilyMember, phase: float, model_times: np.ndarray, count: int,
                         scales: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The motor noise still to come (module docstring, step 4) at ``count`` forecast times, the first ones at the
    member's ``model_times`` (s of model time, from ``phase`` on) and any after them at the last: the member's belief
    given its state at the phase, scaled per state entry by ``scales`` (nx,) and turned onto the direction ``u``
    (d,); (count, nx, nx)."""
    h, H = family.model.h, family.H
    k0 = int(min(round(phase / h), H))
    grid_steps = np.round(model_times / h).astype(int)
    grid_steps[0] = k0
    grid_steps = np.concatenate((grid_steps, [grid_steps[-1]] * (count - len(grid_steps)))).astype(int)
    powers = family.transition_powers[grid_steps - k0]                # A^(j - k0) (K+1, nx, nx)
    cov = member.covariance[grid_steps] - powers @ member.covariance[k0] @ powers.transpose(0, 2, 1)
    cov = 0.5 * (cov + cov.transpose(0, 2, 1))
    frame = family.frame(u)
    return frame @ (cov * np.outer(scales, scales)) @ frame.T


def _phase(tau: np.ndarray, phi: np.ndarray, hand_phi: float, guess: float) -> float:
    """The model time tau (s) at which phi (sampled at ``tau``, (K,)) equals ``hand_phi``: where phi crosses it
    more than once (it rises, then falls in the reach's last steps), the crossing nearest ``guess`` (s, the
    phase at the model's own pace); where it never does, the sample nearest in phi, the earliest first."""
    above = phi >= hand_phi
    crossings = np.flatnonzero(above[1:] != above[:-1])
    if len(crossings) == 0:
        return float(tau[int(np.argmin(np.abs(phi - hand_phi)))])
    w = (hand_phi - phi[crossings]) / (phi[crossings + 1] - phi[crossings])
    found = tau[crossings] + w * (tau[crossings + 1] - tau[crossings])
    return float(found[int(np.argmin(np.abs(found - guess)))])
