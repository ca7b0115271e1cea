"""Rewrite the layer table of docs/architecture.md from the package's import graph (read from the source by
``comanip.caching.module_imports``), so that the table is never typed by hand:

    python -m tools.architecture_layers          # rewrites the blocks between <!-- layers:begin/end --> and
                                                 # <!-- NAME-rooms:begin/end --> for each package of ROOMED

A package that imports no other is at the bottom; any other package is one layer above the highest of those it
imports; layer 1 is the top. So each package imports only packages of higher-numbered layers. The packages of
:data:`ROOMED` are drawn again inside, room by room (their subpackages and top-level modules), by the same rule.
``tests/project/test_architecture.py`` checks the page against the graph.
"""

from __future__ import annotations

import sys
from pathlib import Path

from comanip.caching.module_imports import PACKAGE, import_graph
from tools.result_blocks import replace_block

ARCHITECTURE = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"
ROOMED = ("estimation",)
"""The packages whose rooms (subpackages and top-level modules) have a layer table of their own."""


def package_of(module: str) -> str:
    """The drawn package a module belongs to: ``comanip.planning.starts.x`` -> ``planning/``, ``comanip.model`` ->
    ``model.py``, ``comanip`` -> ``__init__.py``."""
    parts = module.split(".")
    if len(parts) == 1:
        return "__init__.py"
    return f"{parts[1]}/" if (PACKAGE / parts[1]).is_dir() else f"{parts[1]}.py"


def room_of(module: str, package: str) -> str | None:
    """The room of ``package`` a module belongs to (``comanip.estimation.online.x`` -> ``online/``,
    ``comanip.estimation.hand_rest`` -> ``hand_rest.py``, ``comanip.estimation`` -> ``__init__.py``); None
    for a module outside the package."""
    parts = module.split(".")
    if parts[:2] != ["comanip", package]:
        return None
    if len(parts) == 2:
        return "__init__.py"
    return f"{parts[2]}/" if (PACKAGE / package / parts[2]).is_dir() else f"{parts[2]}.py"


def package_graph(package: str | None = None) -> dict[str, dict[str, tuple[str, str]]]:
    """Each package (with ``package``: each of its rooms, :func:`room_of`), the packages (rooms) it imports and, for
    each, one module of it importing one module of the other."""
    part = package_of if package is None else (lambda module: room_of(module, package))
    graph: dict[str, dict[str, tuple[str, str]]] = {}
    for module, imported in import_graph().items():
        if (mine := part(module)) is None:
            continue
        edges = graph.setdefault(mine, {})
        for other in sorted(imported):
            if (theirs := part(other)) is not None and theirs != mine:
                edges.setdefault(theirs, (module, other))
    return graph


def package_layers(graph: dict[str, dict]) -> dict[str, int]:
    """Each package's layer (module docstring); ValueError if packages import one another in a circle."""
    heights: dict[str, int] = {}
    remaining = set(graph)
    while remaining:
        ready = {package for package in remaining if not set(graph[package]) & remaining}
        if not ready:
            raise ValueError(f"packages importing one another in a circle among {sorted(remaining)}")
        for package in ready:
            heights[package] = 1 + max((heights[other] for other in graph[package] if other in heights), default=-1)
        remaining -= ready
    top = max(heights.values())
    return {package: top - height + 1 for package, height in heights.items()}


def layer_table(layers: dict[str, int], graph: dict[str, dict]) -> str:
    """The layer table for ``layers`` with the imports of ``graph``, header included."""
    rows = [f"| {layers.get(package, '?')} | `{package}` | {', '.join(f'`{other}`' for other in sorted(graph[package])) or '–'} |"
            for package in sorted(graph, key=lambda package: (layers.get(package, 0), package))]
    return "\n".join(["| layer | package | imports |", "|---|---|---|", *rows]) + "\n"


def main() -> int:
    text = ARCHITECTURE.read_text(encoding="utf-8")
    for block, package in (("layers", None), *((f"{name}-rooms", name) for name in ROOMED)):
        graph = package_graph(package)
        text = replace_block(text, block, layer_table(package_layers(graph), graph))
    ARCHITECTURE.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
