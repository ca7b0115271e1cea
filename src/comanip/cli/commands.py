"""The subcommands of ``comanip``: where each is implemented and its one-line help, in the order ``comanip
--help`` lists them. Kept apart from the command modules so that listing them imports none."""

COMMANDS = {
    "demo": ("comanip.cli.demo_command", "plan a reach, predict a recorded person's goal online, run a robot beside them"),
    "plan": ("comanip.cli.plan_command", "plan one reach"),
    "validate": ("comanip.cli.validate_command", "compare the model with the paper's validation analyses (and the calibration study, the Franka section)"),
    "transition": ("comanip.cli.transition_command", "transition-point data, model and figure (multi-component reaching)"),
    "handover": ("comanip.cli.handover_command", "robot→person authority handover at the predicted transition"),
    "estimate": ("comanip.cli.estimate_command", "estimate a reach's goal from an observed state"),
    "simulate": ("comanip.cli.simulate_command", "simulate the sync or handover co-manipulation scenario"),
    "fit": ("comanip.cli.fit_command", "fit model parameters to recordings or movement times"),
    "library": ("comanip.cli.library_command", "solve an arm's reach library for cold solves from its ready pose"),
    "ros": ("comanip.cli.ros_command", "the ROS 2 goal node (needs the 'ros' extra)"),
}
"""name -> (module with ``add_parser(subparsers)``, one-line help)"""


def command_help(name: str) -> str:
    return COMMANDS[name][1]
