"""An explanation that vetoes can rule out for the rest of the reach: a stage of the estimator's chain.

:class:`Vetoed` asks its explanation, then, where that explains the hand, its vetoes in order; the first veto
with a reason rules the explanation out, and it stays out until the next reach (a reach whose first part one
account failed to explain is not that account's reach later on). Vetoes are asked only of an account that may
be contested (``Explained.contestable``) that explains the hand or says it misfits it, once the hand has set off
(:meth:`HandTrace.onset`).

The default chain (:mod:`comanip.estimation.online.online_estimator`) vetoes the model at its own pace by its misfit
(:class:`MisfitAbove`) and by its reach at the person's pace where that contradicts its timing
(:class:`~comanip.estimation.online.explanations.person_pace.PaceContradiction`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Protocol

from comanip.estimation.online.explanations.base import Explained, Explanation, HandTrace, Reach, Verdict
from comanip.estimation.online.online_estimate import OnlineEstimate


class Veto(Protocol):
    """A check that may rule another explanation's account out."""

    def reset(self, reach: Reach) -> None:
        """Start a new reach."""

    def veto(self, hand: HandTrace, explained: Explained) -> str | None:
        """Why ``explained``, an account that explains or misfits the hand, is ruled out, or None."""


class MisfitAbove:
    """Rules out an account whose misfit (its own measure, ``Explained.misfit``) is above ``threshold``."""

    def __init__(self, threshold: float, what: str):
        self.threshold, self.what = threshold, what

    def reset(self, reach: Reach) -> None:
        pass

    def veto(self, hand: HandTrace, explained: Explained) -> str | None:
        misfit = explained.misfit
        if misfit is None or misfit <= self.threshold:
            return None
        shown = "inf" if math.isinf(misfit) else f"{misfit:.3g}"
        return f"{self.what} does not explain the hand (misfit {shown} per observed number)"


class Vetoed:
    """``explanation`` ruled out for the rest of the reach by the first of ``vetoes`` with a reason (module docstring)."""

    def __init__(self, explanation: Explanation, vetoes: Sequence[Veto]):
        self.explanation, self.vetoes = explanation, tuple(vetoes)

    def reset(self, reach: Reach) -> None:
        self.reach = reach
        self.explanation.reset(reach)
        for veto in self.vetoes:
            veto.reset(reach)
        self.ruled_out: str | None = None
        """Why the explanation is out for the rest of this reach; None while it is in."""

    def explain(self, hand: HandTrace, latest: OnlineEstimate | None) -> Explained:
        if self.ruled_out is not None:
            return Explained.not_explaining(self.reach, Verdict.RULED_OUT, self.ruled_out)
        explained = self.explanation.explain(hand, latest)
        judged = explained.explains or explained.verdict is Verdict.MISFITS
        if not (judged and explained.contestable and hand.onset() is not None):
            return explained
        why = next((reason for veto in self.vetoes if (reason := veto.veto(hand, explained)) is not None), None)
        if why is None:
            return explained
        self.ruled_out = why
        return replace(explained, verdict=Verdict.RULED_OUT, status=None, message=why)
