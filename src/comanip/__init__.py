"""comanip: predict human reaching with motor-control objectives and plan robot co-manipulation around it.

Haninger & Peternel, "Planning Human-Robot Co-manipulation with Human Motor Control Objectives and
Multi-component Reaching Strategies". See ``comanip.planning.planner`` for the problem statement.
"""

from importlib import import_module

#: the public names and the modules that define them, imported on first use (``import comanip`` stays light,
#: so that ``comanip --help`` does not load the solvers)
_EXPORTS = {
    "presets": "comanip.presets", "ReachingModel": "comanip.model", "Plan": "comanip.planning", "Planner": "comanip.planning",
    "SolverOptions": "comanip.planning", "plan_reach": "comanip.planning", "TransitionModel": "comanip.multicomponent.transition_model",
    "estimate_goal": "comanip.estimation", "goal_posterior": "comanip.estimation", "OnlineGoalEstimator": "comanip.estimation",
    "ReachStream": "comanip.estimation", "OnlineSettings": "comanip.estimation", "fit_model": "comanip.fitting", "fit_movement_times": "comanip.fitting", "fit_timing": "comanip.fitting", "FitResult": "comanip.fitting",
}


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'comanip' has no attribute {name!r}")
    module = import_module(_EXPORTS[name])
    value = module if name == "presets" else getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))


__version__ = "0.1.0"

__all__ = ["presets", "ReachingModel", "Plan", "Planner", "SolverOptions", "plan_reach", "TransitionModel", "estimate_goal", "goal_posterior", "OnlineGoalEstimator",
           "ReachStream", "OnlineSettings", "fit_model", "fit_movement_times", "fit_timing", "FitResult"]
