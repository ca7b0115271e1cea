"""The model's own reaches as the estimators read them: the planner an estimator builds, the reach family and its
cache, a plan played at another timing, the model's reach at a person's pace and its profile fit."""
