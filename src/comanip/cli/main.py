"""Entry point of the ``comanip`` command. Each subcommand lives in its own module with
``add_parser(subparsers)``, which registers the subcommand and sets ``func(args) -> int``; :mod:`comanip.cli.commands`
lists them. A run imports only the module of the subcommand it runs (``comanip --help`` imports none), so that
the command starts without loading the solvers of the others.

Every user mistake ends the command with one line on stderr, ``comanip <command>: error: ...``, and exit
status 2: argparse's own errors (through :class:`OneLineParser`), the ValueError, OSError and YAML errors
raised while loading and checking inputs, and a missing extra (:class:`comanip.extras.MissingExtra`), through
:func:`main`. ``comanip --debug <command>`` shows the traceback.
"""

from __future__ import annotations

import argparse
import sys
from importlib import import_module

import yaml

from comanip import __version__
from comanip.cli.commands import COMMANDS
from comanip.extras import MissingExtra

USER_ERRORS = (ValueError, OSError, yaml.YAMLError, MissingExtra)
"""errors that mean the user gave something wrong (an argument, a file) or asked for a part whose extra is not
installed: one line, exit status 2"""


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line (no usage block), exit status 2, and whose help shows the
    docstrings' reStructuredText literals (``x``) as plain quotes; subparsers inherit it."""

    def format_help(self) -> str:
        return super().format_help().replace("``", "'")

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see '{self.prog} --help')\n")


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The ``comanip`` parser with every subcommand; given the ``argv`` to parse, only the subcommand it names
    is built in full (the others are listed with their one-line help)."""
    parser = OneLineParser(prog="comanip", description="Human reaching prediction and co-manipulation planning.")
    parser.add_argument("--version", action="version", version=f"comanip {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the full traceback of an error")
    subparsers = parser.add_subparsers(dest="command", required=True)
    chosen = None if argv is None else next((word for word in argv if not word.startswith("-")), "")
    for name, (module, help_text) in COMMANDS.items():
        if chosen is None or chosen == name:
            import_module(module).add_parser(subparsers)
        else:
            subparsers.add_parser(name, help=help_text)
    return parser


def one_line(error) -> str:
    """An error (or message) as one line: an OSError as 'strerror: filename', newlines folded into '; '."""
    if isinstance(error, OSError) and error.strerror:
        text = f"{error.strerror}: {error.filename!r}" if error.filename else error.strerror
    else:
        text = str(error) or type(error).__name__
    return "; ".join(line.strip() for line in text.splitlines() if line.strip())


def main(argv: list[str] | None = None) -> int:
    """Run ``comanip argv``; returns the exit status (2 for a user mistake, after one line on stderr)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = build_parser(argv).parse_args(argv)
    except SystemExit as stop:  # --help, or an argument error already printed
        return stop.code if isinstance(stop.code, int) else 2
    try:
        return int(args.func(args) or 0)
    except USER_ERRORS as error:
        if args.debug:
            raise
        print(f"comanip {args.command}: error: {one_line(error)}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
