"""The README and the documentation pages: their snippets run as written and paste into a Python REPL, the
commands they name exist, their links resolve, the results pages' measured tables come from scripts, and
product text names no issue, session or SPEC.

Python: every ```python block runs top to bottom. The README's blocks share ONE namespace (a reader pasting
them into one session); each docs page's blocks share one namespace of their own. Every page's first block
makes its own imports. The blocks run through ``code.InteractiveConsole``, line by line as a REPL reads a
paste, so a block that needs an editor (an indented block followed directly by a dedented line, a blank line
inside a function) fails here. They run in a temporary working directory holding a copy of ``examples/``, so
the shipped example inputs are found at ``examples/data/...`` and files the snippets write land there. A block
whose first line is ``# docs-test: skip`` is not run (none is at present); use it only for a block that
needs hardware or minutes, and say why next to it.

Shell: ```bash blocks are not run (they install packages and take minutes). Every ``comanip <subcommand>``
named in them, or in an inline code span of the prose, must be a subcommand of the ``comanip`` parser, and for
subcommands that take a word of their own (``transition generate``, ``simulate sync``) the second word too.
"""

from __future__ import annotations

import argparse
import code
import importlib.util
import re
import shutil
import sys
from pathlib import Path

import pytest

from comanip.cli.main import build_parser

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md"))
SKIP_MARKER = "# docs-test: skip"


def fenced_blocks(text: str, language: str, name: str = "README.md") -> list[tuple[int, str]]:
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
    assert current is None, f"{name}: unterminated ```{language} block starting at line {start}"
    return blocks


class PastedSession(code.InteractiveConsole):
    """A REPL fed a paste line by line, that records the first error instead of printing it."""

    def __init__(self, namespace: dict):
        super().__init__(namespace)
        self.error: str | None = None

    def showsyntaxerror(self, filename=None, **_):
        kind, value, _ = sys.exc_info()
        self.error = self.error or f"SyntaxError in the REPL: {value}"

    def showtraceback(self):
        kind, value, _ = sys.exc_info()
        self.error = self.error or f"{kind.__name__}: {value}"

    def paste(self, source: str) -> str | None:
        for line in source.splitlines():
            self.push(line)
            if self.error:
                return f"{self.error} (at the line {line.strip()!r})"
        self.push("")   # the Enter that ends a last indented block
        return self.error


def run_page_blocks(path: Path, workdir: Path, monkeypatch) -> dict:
    """Run every Python block of one page in one namespace, as pasted into a REPL; returns the namespace."""
    monkeypatch.chdir(workdir)
    namespace: dict = {"__name__": "__console__"}
    session = PastedSession(namespace)
    name = path.relative_to(ROOT)
    for line, source in fenced_blocks(path.read_text(encoding="utf-8"), "python", str(name)):
        if source.lstrip().startswith(SKIP_MARKER):
            continue
        error = session.paste(source)
        if error:
            pytest.fail(f"{name}: the Python block at line {line} fails: {error}")
    return namespace


@pytest.fixture
def workdir(tmp_path):
    """A working directory with the repository's examples/ (inputs at examples/data/...)."""
    shutil.copytree(ROOT / "examples", tmp_path / "examples", ignore=shutil.ignore_patterns("__pycache__"))
    return tmp_path


PYTHON_PAGES = [README] + [page for page in PAGES if "```python" in page.read_text(encoding="utf-8")]


@pytest.mark.parametrize("page", PYTHON_PAGES, ids=[str(page.relative_to(ROOT)) for page in PYTHON_PAGES])
def test_python_blocks_run_as_pasted_into_a_repl(page, workdir, monkeypatch):
    if "load_cursory(" in page.read_text(encoding="utf-8") and importlib.util.find_spec("cursory") is None:
        pytest.skip("its blocks load recorded people: needs the data extra (pip install -e '.[data]')")
    run_page_blocks(page, workdir, monkeypatch)


def test_the_readme_has_its_quickstart_snippets():
    assert len(fenced_blocks(README.read_text(encoding="utf-8"), "python")) >= 2, "README.md lost its Python snippets?"


def test_the_repl_check_catches_a_block_that_needs_an_editor():
    session = PastedSession({})
    assert session.paste("total = 0\nfor i in range(3):\n    total += i\ntotal\n") is not None
    assert PastedSession({}).paste("total = 0\nfor i in range(3):\n    total += i\n\ntotal\n") is None


def test_readme_saved_model_plans_under_its_own_name(workdir, monkeypatch, capsys):
    """The quickstart saves my.yaml; `comanip plan --preset my.yaml` (as the README says next) reports it by
    the name the snippet gave it, not the preset it was copied from."""
    import json

    from comanip.cli.main import main

    monkeypatch.chdir(workdir)
    exec(compile(fenced_blocks(README.read_text(encoding="utf-8"), "python")[0][1], "README.md:first-block", "exec"), {})
    capsys.readouterr()
    assert main(["plan", "--preset", "my.yaml", "--out", str(workdir / "plan"), "--verbose"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["model"] == "my_model" and summary["success"]


def test_readme_online_snippet_recovers_the_observed_goal(workdir, monkeypatch):
    namespace = run_page_blocks(README, workdir, monkeypatch)
    assert abs(namespace["estimate"].goal - [0.3, 0.1]).max() < 5e-3


def test_goal_estimate_snippets_recover_the_observed_goals(workdir, monkeypatch):
    """The goal-estimation guide observes a plan to [0.3, 0.1] (one-shot: the regret estimate gives it back) and
    a Cartesian reach to [0.3, 0.1, 0.05] (online, from 0.25 s of it)."""
    page = DOCS / "guide" / "goal_estimation.md"
    first, second = [source for _, source in fenced_blocks(page.read_text(encoding="utf-8"), "python")][:2]
    monkeypatch.chdir(workdir)
    namespace: dict = {}
    exec(compile(first, "goal_estimation.md:one-shot", "exec"), namespace)
    estimate, posterior = namespace["estimate"], namespace["posterior"]
    assert estimate.success and abs(estimate.goal - [0.3, 0.1]).max() < 5e-3
    assert posterior.probabilities.shape == (3, 3) and posterior.probabilities[-1].argmax() == 0
    exec(compile(second, "goal_estimation.md:online", "exec"), namespace)
    assert abs(namespace["estimate"].goal - [0.3, 0.1, 0.05]).max() < 0.05


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


COMMAND = re.compile(r"\bcomanip ([a-z][a-z_-]*)(?: ([a-z][a-z_|-]*))?")


def named_commands(text: str, name: str) -> list[tuple[str, str | None, str]]:
    """(subcommand, second word or None, where) for `comanip X [Y]` in bash blocks and inline code spans."""
    found = []
    for line, source in fenced_blocks(text, "bash", name):
        for match in COMMAND.finditer(source):
            found.append((match.group(1), match.group(2), f"{name}: bash block at line {line}"))
    for span in re.findall(r"`([^`\n]+)`", text):
        for match in COMMAND.finditer(span):
            found.append((match.group(1), match.group(2), f"{name}: inline `{span}`"))
    return found


def test_named_commands_exist():
    tree = subcommand_tree()
    commands = [c for page in [README, *PAGES] for c in named_commands(page.read_text(encoding="utf-8"), page.name)]
    assert any("README.md: bash" in where for *_, where in commands), "no comanip command in the README's bash blocks"
    for name, second, where in commands:
        assert name in tree, f"{where}: 'comanip {name}' is not a subcommand (have {sorted(tree)})"
        if tree[name] and second is not None:
            for word in second.split("|"):
                assert word in tree[name], (f"{where}: 'comanip {name} {word}' is not a subcommand of "
                                            f"'{name}' (have {sorted(tree[name])})")


def test_readme_is_short_and_needs_nothing_outside_the_repository():
    """At most 12 KB; no pointer to a shared folder or a SPEC; every relative link resolves inside the repo."""
    text = README.read_text(encoding="utf-8")
    assert len(text.encode("utf-8")) <= 12_000, f"README.md is {len(text.encode())} bytes; move detail to docs/"
    assert "../shared" not in text and "SPEC.md" not in text
    for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
        if "://" in target:
            continue
        path = (ROOT / target).resolve()
        assert path.exists(), f"README links to {target}, which is not in the repository"
        assert ROOT.resolve() in path.parents, f"README links outside the repository: {target}"


#: words of a lab notebook, not of a product: issue numbers, work sessions, the internal SPEC
NOTEBOOK_WORDS = re.compile(r"\b[Ii]ssue \d+|\b[Ss]ession\b|\bSPEC\b")


def product_text_files() -> list[Path]:
    return [README, *PAGES, *sorted((ROOT / "examples").rglob("*.py")), *sorted((ROOT / "examples").rglob("*.yaml")),
            *sorted((ROOT / "src" / "comanip" / "presets").glob("*.yaml"))]


def test_product_text_speaks_of_the_product_only():
    for path in product_text_files():
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
            match = NOTEBOOK_WORDS.search(line)
            assert match is None, f"{path.relative_to(ROOT)}:{number} says {match.group(0)!r}: {line.strip()[:100]}"


def _load(path: Path, name: str):
    """A script of the repository (not part of the package) as a module."""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_cli_reference_has_every_subcommand_and_option():
    """The page the docs hook generates from the parsers: a section per subcommand, every option listed."""
    page = (DOCS / "reference" / "cli.md").read_text(encoding="utf-8")
    for name, words in subcommand_tree().items():
        assert f"## `comanip {name}`" in page, f"no section for comanip {name}"
    plan = build_parser()._subparsers._group_actions[0].choices["plan"]
    for action in plan._actions:
        for flag in action.option_strings:
            if flag not in ("-h", "--help"):
                assert f"`{flag}" in page, f"comanip plan {flag} is missing from the CLI reference"


def test_the_committed_cli_reference_is_the_generated_page():
    """docs/reference/cli.md is what the parsers give today: regenerate it with
    python docs/hooks/cli_reference.py --write after changing a command's arguments or help."""
    hook = _load(DOCS / "hooks" / "cli_reference.py", "cli_reference")
    assert (DOCS / "reference" / "cli.md").read_text(encoding="utf-8") == hook.page_text(), (
        "docs/reference/cli.md is stale: python docs/hooks/cli_reference.py --write")


#: first lines of tables that define settings or vocabulary rather than report measurements
DEFINITION_TABLES = {"| status | where | meaning |", "| script | what it measures | run |"}


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
    """On the results pages (and benchmarks/README.md), a table with a digit in its body is measured: it sits between
    <!-- NAME:begin/end --> markers that tools/regenerate_results.py knows (and rewrites by running the script
    it names). Every block has a script that exists and sits on the page the script says."""
    from tools import regenerate_results as script, result_blocks as blocks
    assert sorted(script.PAGES) == sorted(script.BLOCKS)
    for name, (_, command) in script.BLOCKS.items():
        for word in command:
            if word.endswith((".py", ".yaml")):
                assert (ROOT / word).is_file(), f"block {name}: {word} does not exist"
    for page in [*sorted((DOCS / "results").glob("*.md")), ROOT / "benchmarks" / "README.md"]:
        text = page.read_text(encoding="utf-8")
        names = script.block_names(text)
        assert all(page in script.PAGES[name] for name in names), f"{page.name}: a block its script puts elsewhere"
        spans = blocks.block_spans(text)
        for first, lines in markdown_tables(text):
            if lines[0] in DEFINITION_TABLES or not any(ch.isdigit() for line in lines[2:] for ch in line):
                continue
            inside = [name for name, (begin, end) in spans.items() if begin <= first and first + len(lines) - 1 <= end]
            assert inside, f"{page.name} line {first}: a table of numbers outside any marked block: {lines[0][:80]}"
    for name, pages in script.PAGES.items():
        for page in pages:
            assert name in script.block_names(page.read_text(encoding="utf-8")), f"{page.name} lacks block {name}"


def test_replace_block_rewrites_only_its_block():
    from tools import result_blocks as script
    text = "intro\n<!-- a:begin -->\nold\n<!-- a:end -->\nmiddle\n<!-- b:begin -->\nkeep\n<!-- b:end -->\n"
    assert script.replace_block(text, "a", "new\n") == text.replace("old", "new")
    with pytest.raises(ValueError, match="no block"):
        script.replace_block(text, "c", "x")
    with pytest.raises(ValueError, match="no <!-- a:end -->"):
        script.block_names("<!-- a:begin -->\n")
