"""Every study folder answers its question: its README states the question, the answer with its numbers, the date
and commit it was run at, and the command (a module of the studies package, run from the repository root)."""

import re
from pathlib import Path

import pytest

STUDIES = Path(__file__).resolve().parents[2] / "studies"
FOLDERS = sorted(path for path in STUDIES.iterdir() if path.is_dir() and not path.name.startswith(("_", ".")))


@pytest.mark.parametrize("folder", FOLDERS, ids=lambda folder: folder.name)
def test_a_study_readme_has_its_question_answer_run_and_command(folder):
    text = (folder / "README.md").read_text(encoding="utf-8")
    sections = dict(re.findall(r"^## (\w+)\n(.*?)(?=^## |\Z)", text, re.M | re.S))
    assert text.startswith("# ") and text.splitlines()[0].rstrip().endswith("?"), "the title is the question"
    assert set(sections) >= {"Answer", "Run", "Command"}, sorted(sections)
    assert re.search(r"\d", sections["Answer"]), "the answer gives its numbers"
    assert re.search(r"\b20\d\d-\d\d-\d\d, commit [0-9a-f]{7,40}\b", sections["Run"]), sections["Run"]
    assert f"python -m studies.{folder.name}." in sections["Command"]
