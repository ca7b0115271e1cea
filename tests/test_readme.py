"""The README's snippets run as written and its commands exist.

Python: every ```python block of README.md runs, top to bottom, in ONE shared namespace, as a reader
pasting them into one Python session would; a block may use what an earlier block defined (the imports of
the first block, for instance), and each block defines what else it needs. The blocks run in a fresh
temporary working directory, so files they write (e.g. ``lab.csv``) land there. A block whose first line
is the comment ``# readme-test: skip`` is not run (none is at present); use it only for a block that needs
hardware or minutes, and say why next to it.

Shell: ```bash blocks are not run (they install packages and take minutes). Every ``comanip <subcommand>``
named in them, or in an inline code span of the prose, must be a subcommand of the ``comanip`` parser (the
one ``comanip --help`` prints), and for subcommands that take a word of their own (``transition generate``,
``simulate sync``) the second word must exist too.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from comanip.cli.main import build_parser

README = Path(__file__).resolve().parents[1] / "README.md"
SKIP_MARKER = "# readme-test: skip"


def fenced_blocks(text: str, language: str) -> list[tuple[int, str]]:
    """(first line number, source) of every ```language block, in order."""
    blocks, current, start = [], None, 0
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if current is None and stripped == f"```{language}":
            current, start = [], number + 1
        elif current is not None and stripped == "```":
            blocks.append((start, "\n".join(current) + "\n"))
            current = None
        elif current is not None:
            current.append(line)
    assert current is None, f"README.md: unterminated ```{language} block starting at line {start}"
    return blocks


def subcommand_tree() -> dict[str, set[str]]:
    """{subcommand: the words allowed after it (its subcommands, or simulate's scenarios; empty: none checked)}."""
    def choices(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                return dict(action.choices)
        return {}

    tree = {name: set(choices(sub)) for name, sub in choices(build_parser()).items()}
    from comanip.simulation import SCENARIOS  # `simulate` takes its scenario as a positional word, not a subparser

    tree["simulate"] |= set(SCENARIOS)
    return tree


def test_readme_python_blocks_run_in_order(tmp_path, monkeypatch):
    blocks = fenced_blocks(README.read_text(encoding="utf-8"), "python")
    assert len(blocks) >= 4, "README.md lost its Python snippets?"
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__readme__"}
    for line, source in blocks:
        if source.lstrip().startswith(SKIP_MARKER):
            continue
        try:
            exec(compile(source, f"README.md:{line}", "exec"), namespace)
        except Exception as error:  # name the block in the failure
            pytest.fail(f"the README's Python block at line {line} fails: {type(error).__name__}: {error}")


def test_readme_saved_model_plans_under_its_own_name(tmp_path, monkeypatch, capsys):
    """The first block saves my.yaml; `comanip plan --preset my.yaml` (as the README says next) reports it by
    the name the snippet gave it, not the preset it was copied from."""
    import json

    from comanip.cli.main import main

    source = fenced_blocks(README.read_text(encoding="utf-8"), "python")[0][1]
    monkeypatch.chdir(tmp_path)
    exec(compile(source, "README.md:first-block", "exec"), {})
    assert main(["plan", "--preset", "my.yaml", "--out", str(tmp_path / "plan"), "--verbose"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["model"] == "my_model" and summary["success"]


def test_readme_goal_estimate_snippet_recovers_the_observed_plan_goal(tmp_path, monkeypatch):
    """The goal-estimation snippet observes a plan to [0.3, 0.1]: the regret estimate gives it back."""
    text = README.read_text(encoding="utf-8")
    source = next(src for _, src in fenced_blocks(text, "python") if "estimate_goal" in src)
    monkeypatch.chdir(tmp_path)
    namespace = {"np": __import__("numpy"), "comanip": __import__("comanip")}
    exec(compile(source, "README.md:goal-estimation", "exec"), namespace)
    estimate, posterior = namespace["estimate"], namespace["posterior"]
    assert estimate.success
    assert abs(estimate.goal[0] - 0.3) < 5e-3 and abs(estimate.goal[1] - 0.1) < 5e-3
    assert posterior.probabilities.shape == (3, 3)
    assert posterior.probabilities[-1].argmax() == 0


COMMAND = re.compile(r"\bcomanip ([a-z][a-z_-]*)(?: ([a-z][a-z_|-]*))?")


def named_commands(text: str) -> list[tuple[str, str | None, str]]:
    """(subcommand, second word or None, where) for `comanip X [Y]` in bash blocks and inline code spans."""
    found = []
    for line, source in fenced_blocks(text, "bash"):
        for match in COMMAND.finditer(source):
            found.append((match.group(1), match.group(2), f"bash block at line {line}"))
    for span in re.findall(r"`([^`\n]+)`", text):
        for match in COMMAND.finditer(span):
            found.append((match.group(1), match.group(2), f"inline `{span}`"))
    return found


def test_readme_commands_exist():
    text = README.read_text(encoding="utf-8")
    tree = subcommand_tree()
    commands = named_commands(text)
    assert any(where.startswith("bash") for *_, where in commands), "no comanip command found in a bash block"
    for name, second, where in commands:
        assert name in tree, f"README {where}: 'comanip {name}' is not a subcommand (have {sorted(tree)})"
        if tree[name] and second is not None:
            for word in second.split("|"):
                assert word in tree[name], (f"README {where}: 'comanip {name} {word}' is not a subcommand of "
                                            f"'{name}' (have {sorted(tree[name])})")


def test_readme_needs_nothing_outside_the_repository():
    """No pointer to the session's shared folder or its SPEC; every relative link resolves inside the repo."""
    text = README.read_text(encoding="utf-8")
    assert "../shared" not in text and "SPEC.md" not in text
    root = README.parent
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if "://" in target:
            continue
        path = (root / target).resolve()
        assert path.exists(), f"README links to {target}, which is not in the repository"
        assert root.resolve() in path.parents, f"README links outside the repository: {target}"


def _numbers_script():
    """docs/make_readme_numbers.py as a module (a script, not part of the package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("make_readme_numbers", README.parent / "docs" / "make_readme_numbers.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: first lines of README tables that define settings or vocabulary rather than report measurements
DEFINITION_TABLES = {"| option | default (paper) | what it adds |", "| status | where | meaning |",
                     "| folder (`src/comanip/`) | what lives there |"}


def markdown_tables(text: str) -> list[tuple[int, list[str]]]:
    """(first line number, lines) of every markdown table (a run of lines starting with '|') outside code blocks."""
    tables, current, fenced = [], None, False
    for number, line in enumerate(text.splitlines(), start=1):
        if line.strip().startswith("```"):
            fenced = not fenced
        if not fenced and line.startswith("|"):
            current = current or (number, [])
            current[1].append(line)
        elif current is not None:
            tables.append(current)
            current = None
    return tables + ([current] if current else [])


def test_every_table_of_measured_numbers_is_a_marked_block_with_its_script():
    """A table with a digit in its body is measured: it sits between <!-- NAME:begin/end --> markers that
    docs/make_readme_numbers.py knows (and rewrites by running the script it names), unless it is one of the
    tables of settings above. Every block has a script that exists, and every script's block is in the README."""
    script = _numbers_script()
    text = README.read_text(encoding="utf-8")
    names = script.block_names(text)
    assert sorted(names) == sorted(script.BLOCKS), "README blocks and docs/make_readme_numbers.py's BLOCKS differ"
    for name, (_, command) in script.BLOCKS.items():
        for word in command:
            if word.endswith((".py", ".yaml")):
                assert (README.parent / word).is_file(), f"block {name}: {word} does not exist"
    spans = script.block_spans(text)
    for first, lines in markdown_tables(text):
        if lines[0] in DEFINITION_TABLES or not any(ch.isdigit() for line in lines[2:] for ch in line):
            continue
        inside = [name for name, (begin, end) in spans.items() if begin <= first and first + len(lines) - 1 <= end]
        assert inside, f"README line {first}: a table of numbers outside any marked block: {lines[0][:80]}"


def test_replace_block_rewrites_only_its_block():
    script = _numbers_script()
    text = "intro\n<!-- a:begin -->\nold\n<!-- a:end -->\nmiddle\n<!-- b:begin -->\nkeep\n<!-- b:end -->\n"
    assert script.replace_block(text, "a", "new\n") == text.replace("old", "new")
    with pytest.raises(ValueError, match="no block"):
        script.replace_block(text, "c", "x")
    with pytest.raises(ValueError, match="no <!-- a:end -->"):
        script.block_names("<!-- a:begin -->\n")
