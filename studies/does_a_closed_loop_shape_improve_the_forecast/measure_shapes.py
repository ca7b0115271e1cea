"""Does a closed-loop shape improve the forecast? The forecast's shape against minimum jerk, given the recorded end.

The online estimator's forecast (:func:`comanip.estimation.forecast.hand_forecast.continued_reach`) continues the model's
open-loop plan from rest (the reach family's member at the reach's distance), re-phased to the hand's state. That
plan peaks late (t_peak/MT near 0.48 for the `arm` preset), while a person, and the model executed as a person
executes it (replanning every step), peak earlier. Here each development arm reach, streamed as a live tracker
delivers it, is forecast from its samples at 25 % and 50 % of its movement time, given its recorded endpoint and
end time (so that only the shape differs), by:

- **open-loop plan**: ``continued_reach`` on the estimator's reach family (what the estimator forecasts with);
- **closed-loop reach**: ``continued_reach`` on the same family with each member's mean replaced by the model's
  reach executed in closed loop, replanned every step from the exact state, without noise
  (:func:`comanip.execution.execute_receding_horizon`), to the member's distance;
- **minimum jerk**: the quintic from the hand's position, velocity and acceleration to rest at the endpoint at the
  end time (:func:`comanip.estimation.forecast.path_baselines.minimum_jerk_to`).

Printed as a markdown block (progress on stderr): each shape's t_peak/MT at the reaches' median distance, and the
error / D (median over reaches) of where the hand is at +0.1, +0.2 and +0.3 s.

    PYTHONPATH=src python -m studies.does_a_closed_loop_shape_improve_the_forecast.measure_shapes [--limit N]
"""

from __future__ import annotations

import sys

import numpy as np

import comanip
from comanip.analysis.speed_profile import movement_timing
from comanip.estimation import OnlineGoalEstimator
from comanip.estimation.forecast import path_baselines
from comanip.estimation.forecast.hand_forecast import continued_reach
from comanip.execution import Observation, execute_receding_horizon

from studies.arm_reaches import streamed_arm_reaches  # noqa: E402

FROM = (0.25, 0.5)
LEADS = (0.1, 0.2, 0.3)


class ClosedLoopFamily:
    """A reach family whose members' means are the model's noise-free closed-loop reaches (module docstring); its
    covariances and frames are the open-loop family's. Offers what ``continued_reach`` reads."""

    def __init__(self, family):
        self._family = family
        self.model, self.n, self.nx, self.H, self.blocks = family.model, family.n, family.nx, family.H, family.blocks
        planner = comanip.Planner(self.model)
        self.distances = family.distances
        members = []
        for k, D in enumerate(self.distances):
            run = execute_receding_horizon(planner, np.zeros(self.nx), np.r_[D, np.zeros(self.model.d - 1)], family.width,
                                           steps=self.H, noise=False, observation=Observation(0, 0))
            members.append(run.states.reshape(self.H + 1, self.blocks, self.n)[:, :, 0])
            print(f"closed-loop member {k + 1}/{len(self.distances)}", file=sys.stderr, flush=True)
        self._log_distances, self._members = np.log(self.distances), np.array(members)

    def along(self, distances: np.ndarray) -> np.ndarray:
        """Members' means along the axis per block (M, H+1, blocks), linear in log D between members."""
        x = np.log(np.clip(distances, self.distances[0], self.distances[-1]))
        k = np.clip(np.searchsorted(self._log_distances, x) - 1, 0, len(self.distances) - 2)
        w = ((x - self._log_distances[k]) / (self._log_distances[k + 1] - self._log_distances[k]))[:, None, None]
        return (1 - w) * self._members[k] + w * self._members[k + 1]

    def member_covariance(self, distance: float) -> np.ndarray:
        return self._family.member_covariance(distance)

    def frame(self, u: np.ndarray) -> np.ndarray:
        return self._family.frame(u)


def peak_fraction(family, distance: float) -> float:
    """t_peak / MT of a family's mean reach to ``distance`` m."""
    along = family.along(np.array([distance]))[0]
    return movement_timing(family.model.h * np.arange(family.H + 1), np.abs(along[:, 1])).peak_fraction


def main(argv=None):
    reaches = streamed_arm_reaches(__doc__.split("\n\n")[0], argv)
    model = comanip.presets.arm()
    estimator = OnlineGoalEstimator(model, np.zeros(model.state_size))
    shapes = {"open-loop plan": estimator.family, "closed-loop reach": ClosedLoopFamily(estimator.family)}
    errors = {(name, f, s): [] for name in (*shapes, "minimum jerk") for f in FROM for s in LEADS}
    for i, reach in enumerate(reaches):
        lead = np.array(LEADS)
        for f in FROM:
            k = reach.seen_until(f) - 1
            if k < 1:
                continue
            t_now, x, v = reach.t[k], reach.position[k], reach.velocity[k]
            a = path_baselines.recent_acceleration(reach.t[:k + 1], reach.velocity[:k + 1])
            truth = np.array([reach.position_at(t_now + s) for s in lead])
            paths = {name: continued_reach(family, reach.position[0], t_now, x, v, reach.end,
                                           np.zeros((len(x), len(x))), reach.end_time, a).at(t_now + lead).position
                     for name, family in shapes.items()}
            paths["minimum jerk"] = path_baselines.minimum_jerk_to(x, v, a, reach.end, reach.end_time - t_now, lead)
            for name, path in paths.items():
                for s, error in zip(LEADS, np.linalg.norm(path - truth, axis=1) / reach.distance):
                    errors[name, f, s].append(error)
        print(f"reach {i + 1}/{len(reaches)}", file=sys.stderr, flush=True)
    distance = float(np.median([r.distance for r in reaches]))
    header = " | ".join(f"{int(100 * f)} % +{s:.1f} s" for f in FROM for s in LEADS)
    print(f"The forecast's shape given each reach's recorded endpoint and end time, on the development arm reaches "
          f"({len(reaches)}, streamed at 125 Hz, `arm` preset): where the hand will be, error / D (median over reaches), "
          f"from 25 % and 50 % of MT; t_peak/MT of the shape's reach to the median distance ({distance:.3f} m)\n")
    print(f"| shape | t_peak / MT | {header} |\n|---|---|" + "---|" * (len(FROM) * len(LEADS)))
    for name in (*shapes, "minimum jerk"):
        peak = f"{peak_fraction(shapes[name], distance):.3f}" if name in shapes else "0.5"
        cells = " | ".join(f"{np.median(errors[name, f, s]):.3f}" for f in FROM for s in LEADS)
        print(f"| {name} | {peak} | {cells} |")


if __name__ == "__main__":
    main()
