"""The layers of docs/architecture.md against the package's import graph (read from the source by
comanip.caching.module_imports, imports inside functions and names handed to import_module included): every package
(and every room of a package drawn room by room, tools.architecture_layers.ROOMED) is drawn once, imports only
packages drawn below it, and its row lists exactly what it imports; no module imports itself through others; and
every symbol the page names exists in the package."""

import ast
import re

from comanip.caching.module_imports import PACKAGE, import_graph, module_files
import pytest

from tools.architecture_layers import ARCHITECTURE, ROOMED, layer_table, package_graph, package_layers
ROW = re.compile(r"^\|\s*(\d+)\s*\|\s*`([^`]+)`\s*\|(.*)\|\s*$")


TABLES = [(None, "layers"), *((package, f"{package}-rooms") for package in ROOMED)]
"""(package drawn room by room or None for the whole, its block on the page)."""
tables = pytest.mark.parametrize("package, block", TABLES, ids=[block for _, block in TABLES])


def drawn_layers(block: str = "layers") -> dict[str, tuple[int, set[str]]]:
    """Each package drawn in the layer table ``block`` (``cli/``, ``model.py``, ``__init__.py`` for ``import comanip``;
    a room table's rooms) with its layer (1 at the top) and the packages its row says it imports."""
    text = ARCHITECTURE.read_text()
    table = text[text.index(f"<!-- {block}:begin -->"):text.index(f"<!-- {block}:end -->")]
    drawn = {}
    for line in table.splitlines():
        match = ROW.match(line)
        if match:
            layer, package, imports = match.groups()
            assert package not in drawn, f"{package} is drawn twice"
            drawn[package] = (int(layer), set(re.findall(r"`([^`]+)`", imports)))
    return drawn


@tables
def test_every_package_is_drawn_once(package, block):
    drawn, graph = drawn_layers(block), package_graph(package)
    assert set(drawn) == set(graph), f"drawn but absent: {sorted(set(drawn) - set(graph))}; " \
                                     f"absent from the drawing: {sorted(set(graph) - set(drawn))}"


@tables
def test_no_package_imports_one_drawn_beside_or_above_it(package, block):
    drawn, graph = drawn_layers(block), package_graph(package)
    upward = [f"{package} (layer {drawn[package][0]}) imports {other} (layer {drawn[other][0]}): {module} imports {target}"
              for package, edges in graph.items() for other, (module, target) in edges.items()
              if package in drawn and other in drawn and drawn[other][0] <= drawn[package][0]]
    assert not upward, "\n".join(upward)


@tables
def test_each_row_lists_what_its_package_imports(package, block):
    drawn, graph = drawn_layers(block), package_graph(package)
    differ = {package for package in graph if package in drawn and drawn[package][1] != set(graph[package])}
    assert not differ, f"rows of {sorted(differ)} differ from the import graph (python -m tools.architecture_layers " \
        f"rewrites them); the table should read:\n" + layer_table(package_layers(graph), graph)


def test_the_test_folders_mirror_the_packages():
    """tests/<package>/ holds the tests of src/comanip/<package>/; tests/project/ (what spans the package) and
    tests/data/ (stored reference results) are the only other folders."""
    folders = {path.name for path in ARCHITECTURE.parents[1].joinpath("tests").iterdir()
               if path.is_dir() and not path.name.startswith((".", "__"))}
    packages = {package.rstrip("/") for package in package_graph() if package.endswith("/")}
    assert folders - {"project", "data"} <= packages, sorted(folders - {"project", "data"} - packages)
    for package in ROOMED:     # and a package drawn room by room has a folder of tests for each room it tests
        inside = {path.name for path in ARCHITECTURE.parents[1].joinpath("tests", package).iterdir()
                  if path.is_dir() and not path.name.startswith((".", "__"))}
        rooms = {room.rstrip("/") for room in package_graph(package) if room.endswith("/")}
        assert inside <= rooms, f"tests/{package}/: {sorted(inside - rooms)} are not rooms of {package}/"


def import_circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The sets of modules of ``graph`` (module -> modules it imports) that import one another in a circle: its
    strongly connected components of more than one module, each sorted, in order (Tarjan's algorithm, without
    recursion)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    circles = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        while work:
            module, imported = work[-1]
            other = next(imported, None)
            if other is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[module])
                if low[module] == index[module]:
                    component = stack[stack.index(module):]
                    del stack[stack.index(module):]
                    if len(component) > 1:
                        circles.append(sorted(component))
            elif other not in index:
                index[other] = low[other] = len(index)
                stack.append(other)
                work.append((other, iter(sorted(graph.get(other, ())))))
            elif other in stack:
                low[module] = min(low[module], index[other])
    return sorted(circles)


def test_no_module_imports_itself_through_others():
    """No file-level import circle: a circle inside a package passes the layer check above, but its modules can only
    be read, tested and changed together (imports inside functions count: they hide a circle from Python, not from
    the reader)."""
    circles = import_circles(import_graph())
    assert not circles, "modules importing one another in a circle:\n" + "\n".join(" ".join(c) for c in circles)


def test_a_circle_of_files_is_found(tmp_path):
    """The check above, tried on a package of its own: a imports b at the top, b imports c inside a function, c imports
    a by the name handed to import_module; d imports a and is outside the circle, e imports itself only."""
    package = tmp_path / "pkg"
    package.mkdir()
    sources = {"__init__": "", "a": "from pkg import b\n", "b": "def f():\n    import pkg.c\n",
               "c": "NAME = 'pkg.a'\n", "d": "import pkg.a\n", "e": "import pkg.e\n"}
    for name, source in sources.items():
        (package / f"{name}.py").write_text(source)
    graph = import_graph(package)
    assert import_circles(graph) == [["pkg.a", "pkg.b", "pkg.c"]]
    del graph["pkg.c"]
    assert import_circles(graph) == []


SYMBOL = re.compile(r"`([A-Z][a-z]\w*(?:\.\w+)*|[a-z_]\w*(?:\.\w+)+)(?:\([^`]*\))?`")
"""A code name in backticks: ``Planner``, ``Planner.solve``, ``optim.newton_loop.newton_iterate(...)``."""


def defined_names() -> tuple[dict[str, set[str]], dict[str, set[str]]]:
    """The package's top-level names by module (functions, classes, assignments, imports, the lazily exported
    ``_EXPORTS``) and every class's members by class name (methods, class attributes and fields, ``self.x``
    attributes, and those of its bases in the package)."""
    modules, members, bases = {}, {}, {}
    for name, path in module_files().items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        top = modules.setdefault(name, set())
        for node in tree.body:
            top.update(_bound_names(node))
            if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "_EXPORTS" for t in node.targets):
                top.update(key.value for key in node.value.keys)
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                own = members.setdefault(node.name, set())
                bases.setdefault(node.name, set()).update(ast.unparse(base).split(".")[-1] for base in node.bases)
                for item in node.body:
                    own.update(_bound_names(item))
                own.update(target.attr for inner in ast.walk(node) if isinstance(inner, (ast.Assign, ast.AnnAssign))
                           for target in (inner.targets if isinstance(inner, ast.Assign) else [inner.target])
                           if isinstance(target, ast.Attribute) and getattr(target.value, "id", "") == "self")
    for _ in range(5):  # members of bases, a few generations deep
        for name, parents in bases.items():
            for parent in parents & set(members):
                members[name] |= members[parent]
    return modules, members


def _bound_names(node: ast.stmt) -> set[str]:
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return {node.name}
    if isinstance(node, ast.Assign):
        return {target.id for target in node.targets if isinstance(target, ast.Name)}
    if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
        return {node.target.id}
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        return {(alias.asname or alias.name).split(".")[0] for alias in node.names}
    return set()


def missing_symbols(text: str) -> list[str]:
    """The code names in backticks in ``text`` that the package does not define: a class (or other CamelCase name)
    defined nowhere, ``Class.member`` with no such member, or ``package.module.name`` naming no module or no name in
    it. Lower-case names not starting with a package's folder (``model.body``, an instance's attribute) are not read."""
    modules, members = defined_names()
    everywhere = set(members) | set().union(*modules.values())
    packages = {name.split(".")[1] for name in modules if name.count(".") >= 1 and name.split(".")[1] in
                {path.name for path in PACKAGE.iterdir() if path.is_dir()}}
    missing = []
    for symbol in dict.fromkeys(SYMBOL.findall(text)):
        parts = symbol.split(".")
        if symbol[0].isupper():
            found = parts[0] in everywhere and all(part in members.get(parts[0], set()) for part in parts[1:2])
        elif parts[0] in packages or parts[0] == "comanip":
            dotted = parts if parts[0] == "comanip" else ["comanip", *parts]
            end = max((k for k in range(1, len(dotted) + 1) if ".".join(dotted[:k]) in modules), default=0)
            rest = dotted[end:]
            found = end > 0 and (not rest or rest[0] in modules[".".join(dotted[:end])]) and \
                all(part in members.get(rest[0], set()) for part in rest[1:2])
        else:
            continue
        if not found:
            missing.append(symbol)
    return missing


def test_the_page_names_only_symbols_that_exist():
    assert not missing_symbols(ARCHITECTURE.read_text(encoding="utf-8"))


def test_a_symbol_that_does_not_exist_is_found():
    """The check above, tried: a method, a class and a module function that the package lacks are reported; those
    it has are not."""
    text = ("`Planner.solve` runs `Planner._run_solver`; `StartPolicy.guesses` and `NoSuchPlanner`; "
            "`optim.newton_loop.newton_iterate(method, state)` and `optim.newton_loop.iterate_newton`; `optim.Status`, "
            "`planning.plan.PlanStatus`, `planning.no_module.x`; `model.body.home_position` is an instance's")
    assert missing_symbols(text) == ["Planner._run_solver", "NoSuchPlanner", "optim.newton_loop.iterate_newton",
                                     "planning.no_module.x"]
