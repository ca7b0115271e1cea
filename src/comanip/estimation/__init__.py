"""Estimation from observed reaching: the goal of a reach in progress, and a posterior over candidate goals."""

from comanip.estimation.one_shot.goal_estimate import GoalEstimate
from comanip.estimation.one_shot.goal_estimator import EstimatorCache, EstimatorOptions, GoalEstimator, estimate_goal
from comanip.estimation.one_shot.goal_posterior import GoalPosterior, goal_posterior
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.online.online_estimator import OnlineGoalEstimator
from comanip.estimation.calibration.goal_smoothing import GoalSmoothing
from comanip.estimation.online.online_options import OnlineOptions
from comanip.estimation.calibration.person_calibration import CalibrationSettings, PersonCalibration
from comanip.estimation.streaming.recorded_trials import estimate_recordings
from comanip.estimation.streaming.estimation_loop import EstimationLoop, LoopEvent, LoopSettings, LoopStep
from comanip.estimation.streaming.reach_segmentation import ReachSegmenter, ReachStart, SegmentationSettings
from comanip.estimation.streaming.reach_stream import ReachStream, StreamEstimate
from comanip.estimation.streaming.online_settings import OnlineSettings

__all__ = ["CalibrationSettings", "EstimationLoop", "EstimatorCache", "EstimatorOptions", "GoalEstimate", "GoalEstimator",
           "GoalPosterior", "GoalSmoothing", "LoopEvent", "LoopSettings", "LoopStep", "estimate_goal", "estimate_recordings",
           "goal_posterior", "OnlineEstimate", "OnlineGoalEstimator", "OnlineOptions", "OnlineSettings", "PersonCalibration", "ReachSegmenter", "ReachStart",
           "ReachStream", "SegmentationSettings", "StreamEstimate"]
