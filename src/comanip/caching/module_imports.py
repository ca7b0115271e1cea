"""Which of the package's modules each module imports, read from the source without importing anything.

A module's imports are its ``import comanip.x`` and ``from comanip.x import y`` statements wherever they stand (at
the top, or inside a function, imported on first use) and its string constants that are the dotted name of a
module of the package, alone or as ``module:attribute`` (the names handed to ``importlib.import_module``).
``from comanip.x import y`` imports ``comanip.x.y`` when that is a module, else ``comanip.x``. Module names are
dotted (``comanip.planning.curvature``); a package is named by its ``__init__.py`` (``comanip.planning``).

The compile cache keys compiled functions on the source of the modules they are built from (the modules that import
its builders, :func:`names_imported_from`, and their :func:`import_closure`); the architecture's layer check reads
the package graph from :func:`import_graph`.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]
"""The ``comanip`` folder."""


def module_files(package: Path = PACKAGE) -> dict[str, Path]:
    """Every module of ``package`` by its dotted name (the package's own name is its folder's)."""
    files = {}
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(package.parent).with_suffix("").parts
        files[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return files


def imported_modules(path: Path, modules: set[str]) -> set[str]:
    """The modules of ``modules`` (dotted names) that the source file ``path`` imports."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module is not None and node.level == 0:
            for alias in node.names:
                child = f"{node.module}.{alias.name}"
                found.add(child if child in modules else node.module)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and "." in node.value.split(":")[0] \
                and node.value.split(":")[0] in modules:
            found.add(node.value.split(":")[0])
    return {_owning_module(name, modules) for name in found} - {None}


def _owning_module(name: str, modules: set[str]) -> str | None:
    """``name`` if it is a module, else the longest module it starts with (``comanip.x.y`` of an attribute y of
    ``comanip.x``); None for a name outside ``modules``."""
    parts = name.split(".")
    for end in range(len(parts), 0, -1):
        if ".".join(parts[:end]) in modules:
            return ".".join(parts[:end])
    return None


def names_imported_from(path: Path, module: str) -> set[str]:
    """The names the source file ``path`` imports with ``from module import ...`` (wherever the statement stands)."""
    return {alias.name for node in ast.walk(ast.parse(path.read_text(), str(path)))
            if isinstance(node, ast.ImportFrom) and node.module == module for alias in node.names}


def import_graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    """Each module of ``package`` and the modules of ``package`` it imports (itself left out)."""
    files = module_files(package)
    names = set(files)
    return {name: imported_modules(path, names) - {name} for name, path in files.items()}


def import_closure(roots: set[str], package: Path = PACKAGE) -> set[str]:
    """``roots`` (modules of ``package``) and every module they import, directly or through others (only these
    modules' sources are read)."""
    files = module_files(package)
    names = set(files)
    reached, frontier = set(), list(roots)
    while frontier:
        module = frontier.pop()
        if module not in reached:
            reached.add(module)
            frontier.extend(imported_modules(files[module], names))
    return reached
