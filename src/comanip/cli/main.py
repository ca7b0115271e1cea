"""Entry point of the ``comanip`` command. Each subcommand lives in its own module with
``add_parser(subparsers)``, which registers the subcommand and sets ``func(args) -> int``."""

from __future__ import annotations

import argparse
import sys
from importlib import import_module

#: subcommand modules, in the order ``comanip --help`` lists them
SUBCOMMAND_MODULES = [
    "comanip.cli.plan_command",
    "comanip.cli.validate_command",
    "comanip.cli.transition_command",
    "comanip.cli.handover_command",
    "comanip.cli.estimate_command",
    "comanip.cli.simulate_command",
    "comanip.cli.fit_command",
]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="comanip", description="Human reaching prediction and co-manipulation planning.")
    subparsers = parser.add_subparsers(dest="command", required=True)
    for module in SUBCOMMAND_MODULES:
        import_module(module).add_parser(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as error:
        print(f"comanip {args.command}: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
