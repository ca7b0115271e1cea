"""Estimation from observed reaching: the goal of a reach in progress, and a posterior over candidate goals."""

from comanip.estimation.goal_estimate import GoalEstimate
from comanip.estimation.goal_estimator import EstimatorCache, EstimatorOptions, GoalEstimator, estimate_goal
from comanip.estimation.goal_posterior import GoalPosterior, goal_posterior
from comanip.estimation.online_estimator import OnlineGoalEstimator
from comanip.estimation.goal_smoothing import GoalSmoothing
from comanip.estimation.online_options import OnlineOptions
from comanip.estimation.person_calibration import CalibrationSettings, PersonCalibration
from comanip.estimation.recorded_trials import estimate_recordings
from comanip.estimation.estimation_loop import EstimationLoop, LoopEvent, LoopSettings, LoopStep
from comanip.estimation.reach_segmentation import ReachSegmenter, ReachStart, SegmentationSettings
from comanip.estimation.reach_stream import ReachStream, StreamEstimate

__all__ = ["CalibrationSettings", "EstimationLoop", "EstimatorCache", "EstimatorOptions", "GoalEstimate", "GoalEstimator",
           "GoalPosterior", "GoalSmoothing", "LoopEvent", "LoopSettings", "LoopStep", "estimate_goal", "estimate_recordings",
           "goal_posterior", "OnlineGoalEstimator", "OnlineOptions", "PersonCalibration", "ReachSegmenter", "ReachStart",
           "ReachStream", "SegmentationSettings", "StreamEstimate"]
