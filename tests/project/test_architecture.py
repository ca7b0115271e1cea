"""The layers of docs/architecture.md against the package's import graph (read from the source by
comanip.caching.module_imports, imports inside functions and names handed to import_module included): every package
is drawn once, imports only packages drawn below it, and its row lists exactly what it imports."""

import re
from pathlib import Path

from comanip.caching.module_imports import PACKAGE, import_graph

ARCHITECTURE = Path(__file__).resolve().parents[2] / "docs" / "architecture.md"
ROW = re.compile(r"^\|\s*(\d+)\s*\|\s*`([^`]+)`\s*\|(.*)\|\s*$")


def drawn_layers() -> dict[str, tuple[int, set[str]]]:
    """Each package drawn in the layer table (``cli/``, ``model.py``, ``__init__.py`` for ``import comanip``) with its
    layer (1 at the top) and the packages its row says it imports."""
    text = ARCHITECTURE.read_text()
    table = text[text.index("<!-- layers:begin -->"):text.index("<!-- layers:end -->")]
    drawn = {}
    for line in table.splitlines():
        match = ROW.match(line)
        if match:
            layer, package, imports = match.groups()
            assert package not in drawn, f"{package} is drawn twice"
            drawn[package] = (int(layer), set(re.findall(r"`([^`]+)`", imports)))
    return drawn


def package_of(module: str) -> str:
    """The drawn package a module belongs to: ``comanip.planning.starts.x`` -> ``planning/``, ``comanip.model`` ->
    ``model.py``, ``comanip`` -> ``__init__.py``."""
    parts = module.split(".")
    if len(parts) == 1:
        return "__init__.py"
    return f"{parts[1]}/" if (PACKAGE / parts[1]).is_dir() else f"{parts[1]}.py"


def package_graph() -> dict[str, dict[str, tuple[str, str]]]:
    """Each package, the packages it imports and, for each, one module of it importing one module of the other."""
    graph: dict[str, dict[str, tuple[str, str]]] = {}
    for module, imported in import_graph().items():
        edges = graph.setdefault(package_of(module), {})
        for other in sorted(imported):
            if package_of(other) != package_of(module):
                edges.setdefault(package_of(other), (module, other))
    return graph


def layer_table(layers: dict[str, int], graph: dict[str, dict]) -> str:
    """The layer table's rows for ``layers`` with the imports of ``graph`` (what the page should show)."""
    rows = [f"| {layers.get(package, '?')} | `{package}` | {', '.join(f'`{other}`' for other in sorted(graph[package])) or '–'} |"
            for package in sorted(graph, key=lambda package: (layers.get(package, 0), package))]
    return "\n".join(rows)


def test_every_package_is_drawn_once():
    drawn, graph = drawn_layers(), package_graph()
    assert set(drawn) == set(graph), f"drawn but absent: {sorted(set(drawn) - set(graph))}; " \
                                     f"absent from the drawing: {sorted(set(graph) - set(drawn))}"


def test_no_package_imports_one_drawn_beside_or_above_it():
    drawn, graph = drawn_layers(), package_graph()
    upward = [f"{package} (layer {drawn[package][0]}) imports {other} (layer {drawn[other][0]}): {module} imports {target}"
              for package, edges in graph.items() for other, (module, target) in edges.items()
              if package in drawn and other in drawn and drawn[other][0] <= drawn[package][0]]
    assert not upward, "\n".join(upward)


def test_each_row_lists_what_its_package_imports():
    drawn, graph = drawn_layers(), package_graph()
    differ = {package for package in graph if package in drawn and drawn[package][1] != set(graph[package])}
    assert not differ, f"rows of {sorted(differ)} differ from the import graph; the table should read:\n" + \
        layer_table({package: layer for package, (layer, _) in drawn.items()}, graph)


def test_the_test_folders_mirror_the_packages():
    """tests/<package>/ holds the tests of src/comanip/<package>/; tests/project/ (what spans the package) and
    tests/data/ (stored reference results) are the only other folders."""
    folders = {path.name for path in ARCHITECTURE.parents[1].joinpath("tests").iterdir()
               if path.is_dir() and not path.name.startswith((".", "__"))}
    packages = {package.rstrip("/") for package in package_graph() if package.endswith("/")}
    assert folders - {"project", "data"} <= packages, sorted(folders - {"project", "data"} - packages)
