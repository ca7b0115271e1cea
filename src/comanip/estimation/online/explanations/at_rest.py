"""A hand that has not left its start: nothing is known of the goal beyond the prior.

A tracker's noise makes a resting hand's velocities look like motion; its positions do not
(:mod:`comanip.estimation.hand_rest`). So until a position lies farther than
:data:`~comanip.estimation.hand_rest.REST_RADIUS_M` from the start, this explains the hand with the prior,
status ``uninformative``."""

from __future__ import annotations

from comanip.estimation.online.explanations.base import Explained, HandTrace, Reach, Verdict
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.hand_rest import REST_RADIUS_M
from comanip.estimation.estimate_status import EstimateStatus


class HandAtRest:
    """The prior while the hand has not left its start (module docstring)."""

    def reset(self, reach: Reach) -> None:
        self.reach = reach

    def explain(self, hand: HandTrace, latest: OnlineEstimate | None) -> Explained:
        reach = self.reach
        if hand.has_left(reach.start_position):
            return Explained.not_explaining(reach, Verdict.MISFITS, "the hand has left its start")
        return Explained.explaining(reach.prior_mean, reach.prior_cov, EstimateStatus.UNINFORMATIVE, "the hand has not "
                                    f"left its start (within {1e3 * REST_RADIUS_M:g} mm): the estimate is the prior")
