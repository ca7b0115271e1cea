"""The process's default caches: one per kind, made once even when threads ask at once; their memoised functions;
and no other module-level state in the package (no ``global`` statement, no cache object made at import, no
memoisation, no module-level container written by a function, directly or through an alias, no class-body container
written by its methods), with the check itself tried on added state."""

import ast
import threading
from pathlib import Path

import pytest

from comanip.caching.process_caches import PROCESS_CACHES, ProcessCaches, memoised

SOURCE = Path(__file__).resolve().parents[2] / "src" / "comanip"


def test_a_kind_is_made_once_whoever_asks():
    caches, made = ProcessCaches(), []

    def make():
        made.append(object())
        return made[-1]

    got = []
    threads = [threading.Thread(target=lambda: got.append(caches.get("families", make))) for _ in range(8)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(made) == 1 and all(g is made[0] for g in got)
    assert caches.get("estimators", dict) is not made[0] and caches.kinds() == ["estimators", "families"]


CONTAINERS = ("dict", "list", "set", "bytearray", "defaultdict", "OrderedDict", "Counter", "deque", "ChainMap",
              "WeakValueDictionary", "WeakKeyDictionary", "WeakSet")
"""Calls that make a mutable container (by their last name: ``collections.defaultdict`` is ``defaultdict``)."""
MUTATORS = ("append", "appendleft", "extend", "extendleft", "insert", "update", "setdefault", "pop", "popitem",
            "popleft", "clear", "add", "discard", "remove", "sort", "reverse", "__setitem__", "__delitem__")
"""Methods by which a container is written to."""
MEMOISERS = ("cache", "lru_cache", "cached", "memoize", "memoise")
"""Decorators that keep a function's results (functools', cachetools' and look-alikes), by their last name."""


def _last_name(node: ast.expr) -> str:
    """``lru_cache`` of ``functools.lru_cache(maxsize=8)``, ``lru_cache`` or ``functools.lru_cache``."""
    node = node.func if isinstance(node, ast.Call) else node
    return node.attr if isinstance(node, ast.Attribute) else node.id if isinstance(node, ast.Name) else ""


def _is_container(value: ast.expr | None) -> bool:
    return isinstance(value, (ast.Dict, ast.List, ast.Set, ast.DictComp, ast.ListComp, ast.SetComp)) or \
        (isinstance(value, ast.Call) and _last_name(value) in CONTAINERS)


def _written(node: ast.AST) -> str | None:
    """The name a statement or call writes into (``NAME[k] = v``, ``del NAME[k]``, ``NAME[k] += v``,
    ``NAME.append(v)``, ...), or None."""
    targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) else \
        [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
    for target in targets:
        if isinstance(target, ast.Subscript) and isinstance(target.value, ast.Name):
            return target.value.id
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in MUTATORS \
            and isinstance(node.func.value, ast.Name):
        return node.func.value.id
    return None


def test_a_memoised_function_keeps_its_latest_results_in_the_process_caches():
    calls = []

    @memoised(maxsize=2)
    def square(x):
        calls.append(x)
        return x * x

    assert [square(2), square(2), square(3), square(4), square(2)] == [4, 4, 9, 16, 4]
    assert calls == [2, 3, 4, 2]  # 2 kept, then dropped as the least recently used of three
    assert f"{__name__}.{square.__qualname__}" in PROCESS_CACHES.kinds() and square.__wrapped__(5) == 25
    square.cache_clear()
    square(4)
    assert calls == [2, 3, 4, 2, 5, 4]
    with pytest.raises(ValueError, match="maxsize"):
        memoised(0)


def _memoiser_applied(value: ast.expr | None) -> bool:
    """A memoiser applied by a call, not as a decorator: ``lru_cache(maxsize=8)(f)``, ``cache(f)``."""
    if not isinstance(value, ast.Call):
        return False
    if isinstance(value.func, ast.Call):
        return _last_name(value.func) in MEMOISERS
    return _last_name(value) in MEMOISERS and bool(value.args)


def _class_memos(tree: ast.Module) -> list[str]:
    """Containers made in a class body (shared by every instance) that its methods write into through ``self``,
    ``cls`` or the class's name, where no method gives the instance one of its own (``self.NAME = ...``)."""
    found = []
    for cls in (node for node in ast.walk(tree) if isinstance(node, ast.ClassDef)):
        shared = {}
        for node in cls.body:
            value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
            if _is_container(value):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                shared.update({target.id: node.lineno for target in targets if isinstance(target, ast.Name)})
        owners = {"self", "cls", cls.name}

        def attribute(node):
            return node.attr if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in owners else None

        own = {attribute(target) for node in ast.walk(cls) if isinstance(node, ast.Assign) for target in node.targets}
        for node in ast.walk(cls):
            targets = node.targets if isinstance(node, (ast.Assign, ast.Delete)) else \
                [node.target] if isinstance(node, ast.AugAssign) else []
            written = [attribute(target.value) for target in targets if isinstance(target, ast.Subscript)]
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in MUTATORS:
                written.append(attribute(node.func.value))
            for name in written:
                if name in shared and name not in own:
                    found.append(f"{cls.name}.{name} (line {shared[name]}) written in a method (line {node.lineno})")
    return found


def module_state(source: str) -> list[str]:
    """What the module of ``source`` keeps between calls at module level: global statements, cache objects made at
    import (a call of a class named ...Cache or ...Caches), memoisers (functools' ``cache`` and ``lru_cache``,
    bounded or not, and their look-alikes) as decorators or applied by a call at import, module-level containers that
    a function writes into, directly or through a local name bound to them (a memo dict, a registry filled on use),
    containers in a class body that its methods write into, and functions whose default argument is a container they
    write into."""
    tree = ast.parse(source)
    found = [f"global {', '.join(node.names)} (line {node.lineno})" for node in ast.walk(tree) if isinstance(node, ast.Global)]
    containers = {}
    for node in tree.body:
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        if isinstance(value, ast.Call) and _last_name(value).endswith(("Cache", "Caches")):
            found.append(f"{_last_name(value)}() at import (line {node.lineno})")
        if _memoiser_applied(value):
            found.append(f"{ast.unparse(value)} at import (line {node.lineno})")
        if _is_container(value):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            containers.update({target.id: node.lineno for target in targets if isinstance(target, ast.Name)})
    functions = [node for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))]
    for function in functions:
        positional = [*function.args.posonlyargs, *function.args.args]
        defaulted = [*zip(positional[len(positional) - len(function.args.defaults):], function.args.defaults),
                     *zip(function.args.kwonlyargs, function.args.kw_defaults)]
        mutable_defaults = {argument.arg for argument, default in defaulted if _is_container(default)}
        aliases = {target.id: inner.value.id for inner in ast.walk(function) if isinstance(inner, ast.Assign)
                   and isinstance(inner.value, ast.Name) and inner.value.id in containers
                   for target in inner.targets if isinstance(target, ast.Name)}
        for inner in ast.walk(function):
            name = _written(inner)
            name = aliases.get(name, name)
            if name in containers:
                found.append(f"{name} (line {containers[name]}) written in a function (line {inner.lineno})")
            elif name in mutable_defaults:
                found.append(f"default {name} of a function written in it (line {inner.lineno})")
        for decorator in getattr(function, "decorator_list", []):
            if _last_name(decorator) in MEMOISERS:
                found.append(f"@{ast.unparse(decorator)} on {function.name} (line {function.lineno})")
    return list(dict.fromkeys(found + _class_memos(tree)))


OWNER = "caching/process_caches.py"
"""The one module that may keep state between calls: the process's caches and :func:`memoised`."""


def test_the_package_keeps_no_other_module_level_state():
    offenders = {str(path.relative_to(SOURCE)): state for path in sorted(SOURCE.rglob("*.py"))
                 if str(path.relative_to(SOURCE)) != OWNER and (state := module_state(path.read_text(encoding="utf-8")))}
    assert not offenders, offenders


UNITS_WITH_A_MEMO = '''
_SCALES = {}


def scale_of(unit):
    if unit not in _SCALES:
        _SCALES[unit] = {"m": 1.0, "mm": 1e-3}[unit]
    return _SCALES[unit]
'''


@pytest.mark.parametrize("added, kind", [
    (UNITS_WITH_A_MEMO, "_SCALES (line"),
    ("import functools\n\n@functools.lru_cache(maxsize=8)\ndef f(x):\n    return x\n", "@functools.lru_cache(maxsize=8) on f"),
    ("from functools import cache\n\n@cache\ndef f(x):\n    return x\n", "@cache on f"),
    ("from collections import defaultdict\nSEEN = defaultdict(list)\n\ndef see(k, v):\n    SEEN[k].append(v)\n    SEEN.setdefault(k, [])\n", "SEEN (line"),
    ("_LOG = []\n\ndef log(x):\n    _LOG.append(x)\n", "_LOG (line"),
    ("def f(x, _memo={}):\n    _memo[x] = x\n    return _memo[x]\n", "default _memo"),
    ("from comanip.caching.model_cache import ModelCache\nCACHE = ModelCache()\n", "ModelCache() at import"),
    ("_N = 0\n\ndef count():\n    global _N\n    _N += 1\n", "global _N"),
    ("class Scales:\n    _known = {}\n\n    def of(self, unit):\n        self._known[unit] = 1.0\n", "Scales._known"),
    ("class Scales:\n    seen = []\n\n    @classmethod\n    def see(cls, x):\n        cls.seen.append(x)\n", "Scales.seen"),
    ("import functools\n\ndef _f(x):\n    return x\n\nf = functools.lru_cache(maxsize=8)(_f)\n", "functools.lru_cache(maxsize=8)(_f) at import"),
    ("from functools import cache\n\ndef _f(x):\n    return x\n\nf = cache(_f)\n", "cache(_f) at import"),
    ("_SEEN = {}\n\ndef see(k):\n    table = _SEEN\n    table[k] = True\n", "_SEEN (line"),
])
def test_module_state_is_found_when_added_to_a_module(added, kind):
    """The check above, tried: each way of keeping state between calls, added to the source of units.py, is
    reported; units.py as it is reports nothing."""
    units = (SOURCE / "units.py").read_text(encoding="utf-8")
    assert module_state(units) == []
    assert any(kind in state for state in module_state(units + "\n" + added)), module_state(units + "\n" + added)


def test_constant_tables_and_import_time_filling_are_not_state():
    """A module-level table read by functions, or filled once while the module is imported, keeps nothing between
    calls; nor does a class-body container an instance replaces with one of its own, or a memoiser an instance
    applies to its own method."""
    source = ('NAMES = {"a": 1}\nORDER = []\nfor name in NAMES:\n    ORDER.append(name)\n\n'
              'def lookup(key, table={}):\n    local = {}\n    local[key] = NAMES[key]\n    return table.get(key, local[key])\n\n'
              'class Owner:\n    items = []\n\n    def __init__(self):\n        self.items = []\n'
              '        self.square = functools.lru_cache(maxsize=4)(self._square)\n\n'
              '    def add(self, x):\n        self.items.append(x)\n')
    assert module_state(source) == []
