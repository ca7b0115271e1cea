"""The reaching model's mean reach at the person's own pace and onset (:mod:`comanip.estimation.model_reaches.paced_model`).

It explains the hand where that fit does (misfit at most ``OnlineOptions.paced_threshold``) and pins the goal's
distance (:meth:`ModelAtPersonPace.settled`). Its goal is combined with the prior and never lies behind a hand
that has moved past it; its covariance is the fit's plus the spread of the model's reach around its goal at
the end (where the hand stops spreads as the model's own reach to it does).

Where it pins the goal at a pace or onset far from the model's own, it contradicts the model at its own pace
(:class:`PaceContradiction`, a veto of :mod:`comanip.estimation.online.explanations.vetoed`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2

from comanip.estimation.online.explanations.base import Explained, HandTrace, Reach, Verdict
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.online.online_options import OnlineOptions
from comanip.estimation.model_reaches.paced_model import PacedFit, PacedModel
from comanip.optim import Status

SETTLED_SPREAD = 0.1
"""A paced fit whose relative std of the goal's distance is at most this pins the goal."""
SETTLED_OBSERVATIONS = 8
"""Observations since the onset a paced fit needs to pin the goal."""
PACE_TOLERANCE = 0.14
"""|log pace|, and |onset delay| / MT, beyond which a settled paced fit contradicts the model's own timing."""


class ModelAtPersonPace:
    """The model's reach at the person's pace (module docstring), fitted once per observation."""

    def __init__(self, paced: PacedModel, options: OnlineOptions):
        self.paced, self.options = paced, options

    def reset(self, reach: Reach) -> None:
        self.reach = reach
        self._fitted: tuple[int, PacedFit] | None = None

    def fit(self, hand: HandTrace, goal) -> PacedFit:
        """The paced fit to the observations so far (the first one asked for since the newest observation): its
        shape tried at the distance the previous fit found, or on the first fit at the distance of ``goal`` (kept
        between 1 and 3 times the hand's displacement: a shape far from the distance it fits can lock into a
        wrong pace and distance) and at 1.5 times the displacement."""
        if self._fitted is not None and self._fitted[0] == hand.count:
            return self._fitted[1]
        start = self.reach.start_position
        displacement = max(float(np.linalg.norm(hand.position[-1] - start)), 1e-3)
        if self._fitted is not None:
            guesses = [float(np.linalg.norm(self._fitted[1].goal - start))]
        else:
            guesses = [1.5 * displacement]
            if goal is not None:
                guesses.insert(0, min(max(float(np.linalg.norm(np.asarray(goal) - start)), displacement), 3 * displacement))
        fitted = self.paced.fit(hand.t, hand.position, hand.velocity, start, hand.onset(), guesses)
        self._fitted = (hand.count, fitted)
        return fitted

    def explain(self, hand: HandTrace, latest: OnlineEstimate | None) -> Explained:
        reach = self.reach
        if hand.onset() is None:
            return Explained.not_explaining(reach, Verdict.UNDECIDED, "nor does it at the person's pace (no movement seen)")
        fitted = self.fit(hand, None if latest is None else latest.goal)
        if fitted.misfit > self.options.paced_threshold:
            return Explained.not_explaining(reach, Verdict.MISFITS, f"nor does it at the person's pace (misfit "
                                            f"{fitted.misfit:.3g})", goal=fitted.goal, covariance=fitted.covariance,
                                            misfit=fitted.misfit)
        if not self.settled(fitted):
            return Explained.not_explaining(reach, Verdict.UNDECIDED, f"nor does it clearly at the person's pace (misfit "
                                            f"{fitted.misfit:.3g}, the goal's distance not pinned yet)", goal=fitted.goal,
                                            covariance=fitted.covariance, misfit=fitted.misfit)
        landing = reach.prediction(fitted.goal, order=0).cov[-1, :reach.model.n, :reach.model.n]
        return reach.landed(Explained.explaining(fitted.goal, fitted.covariance + landing, Status.SOLVED, "the model's reach "
                                                 f"at the person's pace (×{fitted.pace:.3g}, onset {fitted.onset:.3g} s) does",
                                                 misfit=fitted.misfit, timing=fitted.timing), hand.position[-1])

    def settled(self, fitted: PacedFit) -> bool:
        """Whether a paced fit pins the goal's distance: its relative std along the reach at most
        :data:`SETTLED_SPREAD` (before the speed peaks, a shorter quicker and a longer slower reach fit alike),
        from at least :data:`SETTLED_OBSERVATIONS` observations since the onset."""
        if fitted.observations < SETTLED_OBSERVATIONS:
            return False
        offset = fitted.goal - self.reach.start_position
        distance = float(np.linalg.norm(offset))
        return distance > 0 and math.sqrt(float(offset @ fitted.covariance @ offset)) / distance**2 <= SETTLED_SPREAD



class PaceContradiction:
    """A veto of the model at its own pace by its reach at the person's pace (``paced``, whose fit it shares).

    It rules the account out where the paced fit explains the hand, pins the goal, finds a pace off the model's
    by more than :data:`PACE_TOLERANCE` (as a log) or an onset off the model's by more than that fraction of the
    movement time, and a goal the account's 99.9 % region (with the paced fit's) does not hold."""

    def __init__(self, paced: ModelAtPersonPace):
        self.paced = paced

    def reset(self, reach: Reach) -> None:
        self.paced.reset(reach)

    def veto(self, hand: HandTrace, explained: Explained) -> str | None:
        paced = self.paced
        fitted = paced.fit(hand, explained.goal)
        on_time = abs(math.log(fitted.pace)) <= PACE_TOLERANCE and abs(fitted.delay) <= PACE_TOLERANCE * fitted.duration
        if fitted.misfit > paced.options.paced_threshold or not paced.settled(fitted) or on_time:
            return None
        difference = fitted.goal - explained.goal
        distance2 = float(difference @ np.linalg.solve(fitted.covariance + explained.covariance, difference))
        if distance2 <= chi2.ppf(0.999, len(difference)):
            return None
        return (f"the model at its own pace is contradicted by its reach at the person's pace (×{fitted.pace:.3g}, "
                f"{fitted.delay:+.3g} s late), whose goal lies {math.sqrt(distance2):.3g} standard deviations away")
