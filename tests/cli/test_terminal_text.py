"""What the commands print on the terminal: the version, and a fit's summary without the optimiser's own words."""

from pathlib import Path

import pytest

import comanip
from comanip.cli.main import main

ROOT = Path(__file__).resolve().parents[2]


def test_version_prints_the_package_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"comanip {comanip.__version__}"


@pytest.mark.slow
def test_fit_prints_its_summary_without_scipys_message(tmp_path, capsys):
    argv = ["fit", "--recordings", str(ROOT / "examples" / "data" / "recordings"), "--preset", "planar", "--parameters", "kappa",
            "--out", str(tmp_path / "fit"), "--no-progress"]
    assert main(argv) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].startswith("fit (planar): converged: kappa = ")
    assert len(lines) == 2 and lines[1].startswith("wrote 3 files"), lines
    assert not any("Optimization" in line or "termination" in line for line in lines)
