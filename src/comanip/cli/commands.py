"""The subcommands of ``comanip``: where each is implemented and its one-line help, in the order ``comanip
--help`` lists them. Kept apart from the command modules so that listing them imports none."""

from comanip.cli.command_help import COMMAND_HELP

COMMANDS = {name: (module, COMMAND_HELP[name]) for name, module in (
    ("demo", "comanip.cli.demo_command"),
    ("plan", "comanip.cli.plan_command"),
    ("replan", "comanip.cli.replan_command"),
    ("validate", "comanip.cli.validate_command"),
    ("transition", "comanip.cli.transition_command"),
    ("handover", "comanip.cli.handover_command"),
    ("estimate", "comanip.cli.estimate_command"),
    ("simulate", "comanip.cli.simulate_command"),
    ("fit", "comanip.cli.fit_command"),
    ("library", "comanip.cli.library_command"),
    ("ros", "comanip.cli.ros_command"),
)}
"""name -> (module with ``add_parser(subparsers)``, one-line help)"""
