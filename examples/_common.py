"""What every example shares: where its figure goes, and how big a run it makes.

COMANIP_EXAMPLES_OUT (default out/examples): the folder of the figures.
COMANIP_EXAMPLES_SMALL=1: the smallest run that still shows the concept (the tests use it).
"""

import os
from pathlib import Path

SMALL = os.environ.get("COMANIP_EXAMPLES_SMALL", "") not in ("", "0")
DATA = Path(__file__).resolve().parent / "data"


def figure_path(name: str) -> Path:
    """out/examples/<name>.png (or under COMANIP_EXAMPLES_OUT), its folder created."""
    folder = Path(os.environ.get("COMANIP_EXAMPLES_OUT", "out/examples"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder / f"{name}.png"
