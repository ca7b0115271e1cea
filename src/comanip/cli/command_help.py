"""The one-line help of each subcommand of ``comanip``, read by the command modules as they register their parser
and by :mod:`comanip.cli.commands` for the listing (a module of its own, so that a command importing its help
imports no other command)."""

COMMAND_HELP = {
    "demo": "plan a reach, predict a recorded person's goal online, run a robot beside them",
    "plan": "plan one reach",
    "replan": "replan a reach in closed loop at a controller's rate, beside the converged loop",
    "validate": "compare the model with the paper's validation analyses (and the calibration study, the Franka section)",
    "transition": "transition-point data, model and figure (multi-component reaching)",
    "handover": "robot→person authority handover at the predicted transition",
    "estimate": "estimate a reach's goal from an observed state",
    "simulate": "simulate the sync or handover co-manipulation scenario",
    "fit": "fit model parameters to recordings or movement times",
    "library": "solve an arm's reach library for cold solves from its ready pose",
    "ros": "the ROS 2 goal node (needs the 'ros' extra)",
}
"""name -> one-line help"""


def command_help(name: str) -> str:
    return COMMAND_HELP[name]
