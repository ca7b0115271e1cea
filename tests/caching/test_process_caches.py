"""The process's default caches: one per kind, made once even when threads ask at once; and no other module-level
state in the package (no ``global`` statement, no cache object made at import, no unbounded memoisation)."""

import ast
import threading
from pathlib import Path

from comanip.caching.process_caches import ProcessCaches

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


def module_state(path: Path) -> list[str]:
    """What in ``path`` keeps state at module level: global statements, cache objects made at import (a call of a
    class named ...Cache or ...Caches), and memoisation without a bound."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = [f"global {', '.join(node.names)} (line {node.lineno})" for node in ast.walk(tree) if isinstance(node, ast.Global)]
    for node in tree.body:
        value = node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None
        if isinstance(value, ast.Call) and isinstance(value.func, ast.Name) and value.func.id.endswith(("Cache", "Caches")):
            found.append(f"{value.func.id}() at import (line {node.lineno})")
    for node in ast.walk(tree):
        for decorator in getattr(node, "decorator_list", []):
            text = ast.unparse(decorator)
            if text in ("cache", "functools.cache") or ("lru_cache" in text and "maxsize=None" in text):
                found.append(f"@{text} on {node.name} (line {node.lineno})")
    return found


def test_the_package_keeps_no_other_module_level_state():
    offenders = {str(path.relative_to(SOURCE)): state for path in sorted(SOURCE.rglob("*.py"))
                 if (state := module_state(path)) and path.name != "process_caches.py"}
    assert not offenders, offenders
