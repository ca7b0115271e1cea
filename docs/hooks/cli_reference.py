"""The command-line reference page, ``docs/reference/cli.md``, generated from the ``comanip`` argparse parsers.

The page is :data:`INTRODUCTION` followed by one section per subcommand (and per sub-subcommand, e.g.
``transition generate``): its description, its usage line and a table of its arguments with their defaults and
help, exactly as ``comanip X --help`` has them. Nothing is typed by hand. The page is kept in the repository,
so that it reads where users land; ``python docs/hooks/cli_reference.py --write`` regenerates it, ``--check``
exits 1 when it is stale (the tests run that check), and as an MkDocs hook it warns at build time when the
page is stale (a failure under ``--strict``).
"""

from __future__ import annotations

import argparse
import inspect
import logging
import re
import sys
from pathlib import Path

PAGE = Path(__file__).resolve().parents[1] / "reference" / "cli.md"
INTRODUCTION = """# Command line

Every subcommand of `comanip`, its arguments, defaults and help, generated from the command's own parsers
(`python docs/hooks/cli_reference.py --write`; a test fails when this page is stale), so it matches
`comanip X --help`. Every user mistake ends a command with one line on stderr (`comanip X: error: …`) and exit
status 2; `comanip --debug X …` shows the traceback instead. `comanip --version` prints the version.
"""


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _plain(text: str) -> str:
    """Help text as markdown: reStructuredText literals as code, table cells on one line."""
    text = re.sub(r"``([^`]+)``", r"`\1`", text or "")
    return " ".join(text.split()).replace("|", "\\|")


def _argument(action: argparse.Action) -> str:
    if action.option_strings:
        names = ", ".join(action.option_strings)
        if action.nargs != 0:
            names += f" {action.metavar or action.dest.upper()}"
        return f"`{names}`"
    return f"`{action.metavar or action.dest}`"


def _default(action: argparse.Action) -> str:
    default = action.default
    if action.nargs == 0 or action.required or default is None or (isinstance(default, str) and default == argparse.SUPPRESS):
        return ""
    if isinstance(default, (list, tuple)) or type(default).__module__ == "numpy":
        default = ",".join(str(float(x)) for x in default) if hasattr(default, "__iter__") else default
    return f"`{default}`"


def parser_markdown(parser: argparse.ArgumentParser, level: int = 2) -> str:
    """One section: heading, description, usage and the argument table; then its subcommands' sections."""
    formatter = parser._get_formatter()
    lines = [f"{'#' * level} `{parser.prog}`", ""]
    if parser.description:
        # cleaned as Python 3.13 cleans a docstring at compile time, so that every Python writes the same page
        lines += ["```text", inspect.cleandoc(parser.description).replace("``", "'").strip(), "```", ""]
    usage = formatter._format_usage(parser.usage, parser._actions, parser._mutually_exclusive_groups, "")
    lines += ["```text", " ".join(usage.split()), "```", ""]
    rows = [action for action in parser._actions
            if not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)) and action.help != argparse.SUPPRESS]
    if rows:
        lines += ["| argument | default | meaning |", "|---|---|---|"]
        for action in rows:
            help_text = formatter._expand_help(action) if action.help else ""
            choices = f" (one of: {', '.join(map(str, action.choices))})" if action.choices and not isinstance(
                action.choices, dict) else ""
            lines.append(f"| {_argument(action)} | {_default(action)} | {_plain(help_text)}{_plain(choices)} |")
        lines.append("")
    for child in _subparsers(parser).values():
        lines.append(parser_markdown(child, level + 1))
    return "\n".join(lines)


def cli_markdown() -> str:
    """The reference of every ``comanip`` subcommand, in the order ``comanip --help`` lists them."""
    from comanip.cli.main import build_parser

    root = build_parser()
    sections = [parser_markdown(child) for child in _subparsers(root).values()]
    return "\n".join(sections)


def page_text() -> str:
    """The whole page: the introduction, then :func:`cli_markdown`."""
    return INTRODUCTION + "\n" + cli_markdown()


def on_page_markdown(markdown: str, page, **_) -> str:
    """MkDocs event: warn (a failure under --strict) when the committed page is not the generated one."""
    if page is not None and page.file.src_uri == "reference/cli.md" and PAGE.read_text(encoding="utf-8") != page_text():
        logging.getLogger("mkdocs.plugins.cli_reference").warning(
            "docs/reference/cli.md is stale: regenerate it with python docs/hooks/cli_reference.py --write")
    return markdown


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        PAGE.write_text(page_text(), encoding="utf-8")
    elif sys.argv[1:] == ["--check"]:
        sys.exit(0 if PAGE.read_text(encoding="utf-8") == page_text() else "docs/reference/cli.md is stale: "
                 "python docs/hooks/cli_reference.py --write")
    else:
        sys.stdout.write(page_text())
