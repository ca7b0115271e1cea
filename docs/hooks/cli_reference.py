"""MkDocs hook: the CLI reference page, generated from the ``comanip`` argparse parsers at every build.

The page ``reference/cli.md`` holds the line ``<!-- cli-reference -->``; this hook replaces it with one section
per subcommand (and per sub-subcommand, e.g. ``transition generate``): its description, its usage line and a
table of its arguments with their defaults and help, exactly as ``comanip X --help`` has them. Nothing is
typed by hand, so the page cannot go stale. Also runnable on its own:
``python docs/hooks/cli_reference.py > cli.md``.
"""

from __future__ import annotations

import argparse
import re
import sys

MARKER = "<!-- cli-reference -->"


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
        lines += ["```text", parser.description.replace("``", "'").strip(), "```", ""]
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


def on_page_markdown(markdown: str, page, **_) -> str:
    """MkDocs event: fill the marker of the CLI reference page."""
    if MARKER in markdown:
        markdown = markdown.replace(MARKER, cli_markdown())
    return markdown


if __name__ == "__main__":
    sys.stdout.write(cli_markdown())
