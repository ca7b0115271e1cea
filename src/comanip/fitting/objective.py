"""The negative log-likelihood of a set of recordings as a function of the transformed parameters u."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from comanip.fitting.condition_plans import ConditionPlanner
from comanip.fitting.conditions import Condition
from comanip.fitting.likelihood import trial_nll
from comanip.fitting.parameters import ParameterSpace
from comanip.recordings.trial_files import Trial
from comanip.planning.plan import Plan


class RecordingsObjective:
    """u (p,) -> NLL: set the model's free parameters, plan every condition, sum the trials' NLLs.

    Evaluations are memoised by u (the optimiser and the Hessian revisit points). A value the model
    rejects gives inf.
    """

    def __init__(self, trials: list[Trial], conditions: list[Condition], space: ParameterSpace,
                 planner: ConditionPlanner, on_evaluation: Callable[[float], None] | None = None):
        self.trials, self.conditions, self.space, self.planner = trials, conditions, space, planner
        self.on_evaluation = on_evaluation
        self._memo: dict[bytes, tuple[np.ndarray, list[Plan] | None]] = {}

    @property
    def evaluations(self) -> int:
        """Distinct points evaluated so far."""
        return len(self._memo)

    def __call__(self, u) -> float:
        return float(np.sum(self.per_trial(u)))

    def per_trial(self, u) -> np.ndarray:
        """NLL (nats) of each trial (K,) at u."""
        return self._evaluate(u)[0]

    def plans(self, u) -> list[Plan] | None:
        """The conditions' plans at u (None when the model rejected u)."""
        return self._evaluate(u)[1]

    def _evaluate(self, u) -> tuple[np.ndarray, list[Plan] | None]:
        u = np.asarray(u, dtype=float)
        key = u.tobytes()
        if key not in self._memo:
            try:
                model = self.space.model_for(u)
            except ValueError:
                self._memo[key] = (np.full(len(self.trials), np.inf), None)
            else:
                plans = self.planner.plans(model)
                self._memo[key] = (self._trial_nlls(plans, self.space.noise_for(u)), plans)
            if self.on_evaluation is not None:
                self.on_evaluation(float(np.sum(self._memo[key][0])))
        return self._memo[key]

    def _trial_nlls(self, plans: list[Plan], sigma_obs: float) -> np.ndarray:
        nll = np.empty(len(self.trials))
        for condition, plan in zip(self.conditions, plans):
            for k in condition.trials:
                trial = self.trials[k]
                nll[k] = trial_nll(plan, trial, trial.start - condition.start, sigma_obs)
        return nll
