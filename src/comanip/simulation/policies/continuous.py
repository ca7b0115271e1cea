"""(e) comanip's continuous estimate: the robot feeds every observation of the handle, one every
``update_interval`` from the start of the reach, through an :class:`~comanip.estimation.EstimationLoop` to its
online estimator (the ``sync_robot`` description, :mod:`comanip.estimation.streaming.online_settings`) and, from t_o
on, leads along the model's whole reach to the latest estimate's goal at the estimate's timing
(``estimate.timed_reach``), replanned at every update. Not along the estimate's forecast of the hand: that starts
at the handle, which the robot itself moves on the axes it leads, so leading along it feeds the robot's own motion
back into its lead."""

from __future__ import annotations

import dataclasses

import numpy as np

from comanip.estimation import PersonCalibration
from comanip.estimation.online.online_estimator import OnlineGoalEstimator
from comanip.estimation.streaming import online_settings
from comanip.estimation.streaming.online_settings import OnlineSettings
from comanip.simulation.policies.protocol import PolicyContext, Prediction
from comanip.simulation.rest_trajectory import RestTrajectory

ROBOT_ESTIMATOR = "sync_robot"
"""The description of the robot's estimator (:func:`comanip.estimation.streaming.online_settings.load`): a person
who corrects deviations from their plan, as the simulated person does by replanning, the robot-led z read as less
informative from t_o on, the goal covariance calibrated, a prior goal of 0.25 m per axis."""


def robot_estimation(context: PolicyContext, settings: OnlineSettings | None = None) -> OnlineSettings:
    """The robot's online estimation in ``context``: ``settings`` (default :data:`ROBOT_ESTIMATOR`) with the
    context's model, width, t_o (from which the robot leads its axes) and update rate, one reach from the first
    sample."""
    settings = online_settings.load(ROBOT_ESTIMATOR) if settings is None else settings
    return settings.replace(options=dataclasses.replace(settings.options, led_from=context.observation_time),
                            width=context.online_width,
                            loop=dataclasses.replace(settings.loop, segmentation=None, rate=1.0 / context.update_interval))


class ContinuousPolicy:
    """The online MAP goal and its predicted reach, revised with each observation.

    settings: the robot's :class:`~comanip.estimation.streaming.online_settings.OnlineSettings` (default
    :data:`ROBOT_ESTIMATOR`); its model is the context's, its t_o, update rate and width the context's
    (:func:`robot_estimation`).
    """

    name = "continuous"
    leads_height = True

    def __init__(self, context: PolicyContext, settings: OnlineSettings | None = None):
        self.context = context
        self.update_interval = context.update_interval
        self.settings = robot_estimation(context, settings)
        self.loop = self.settings.estimation_loop(context.start, prior_goal=context.prior_goal, model=context.online_model,
                                                  person=context.person)
        """The loop that paces the robot's observations (:class:`~comanip.estimation.EstimationLoop`): one reach, from
        the trial's start at t = 0, for the context's person (a person not seen yet when it has none)."""
        self.loop.begin(0.0, context.start[:context.online_model.n])

    @property
    def estimator(self) -> OnlineGoalEstimator:
        """The robot's online estimator."""
        return self.loop.estimator

    def finish_trial(self) -> PersonCalibration:
        """The trial is over: learn the person from its reach (where the hand came to rest away from its start;
        :meth:`~comanip.estimation.online.online_estimator.OnlineGoalEstimator.finish_reach`) and return what the
        robot now knows of them, for the next trial's context (``PolicyContext.person``)."""
        self.estimator.finish_reach()
        return self.estimator.person

    def observe(self, t: float, position: np.ndarray, velocity: np.ndarray, force: np.ndarray) -> None:
        self.loop.add_sample(t, position, velocity)
        update = self.loop.take_due()
        if update is not None:
            self.loop.estimate(update)

    def predict(self, t: float) -> Prediction | None:
        """The latest estimate's goal and the model's reach to it at its timing; None (do not lead yet) before the first observation,
        e.g. when update_interval is longer than t_o."""
        c, estimate = self.context, self.estimator.latest
        if estimate is None:
            return None
        return Prediction(np.array(estimate.goal), RestTrajectory.from_timed_reach(estimate.timed_reach, c.dt, c.duration), estimate)
