"""The outcomes of a goal estimate or posterior that are not a solver's (:class:`comanip.optim.Status`), and the
statuses that count as a successful estimate."""

from __future__ import annotations

from enum import StrEnum

from comanip.optim import CONVERGED


class EstimateStatus(StrEnum):
    """How an estimate ended when no solver's outcome says it. A ``str``, like :class:`comanip.optim.Status`."""

    UNINFORMATIVE = "uninformative"
    """The observation says nothing about the goal (it is the start itself)."""
    PEOPLE_MODEL = "people_model"
    """A goal estimate from the model fitted to recorded people (:mod:`comanip.estimation.people.people_model`): the
    reaching model at its own pace does not explain the observed hand."""
    AT_RANGE_END = "at_range_end"
    """The online MAP goal sits at the largest distance its reach family covers: the observations point farther
    than the model's plans reach, so the goal found is the range's end, not a solution."""
    PLANS_NOT_CONVERGED = "plans_not_converged"
    """A goal posterior some of whose candidates' plans did not converge."""


ESTIMATED = CONVERGED | {EstimateStatus.PEOPLE_MODEL}
"""The statuses of a successful estimate: a converged solve, or the people model's goal."""
