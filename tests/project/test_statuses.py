"""Statuses are compared and set by their enums (comanip.optim.Status, PlanStatus, EstimateStatus, FitStatus), never
as string literals in the package: a renamed or mistyped status then fails at import, not silently at run time."""

import ast
from pathlib import Path

from comanip.estimation.estimate_status import EstimateStatus
from comanip.fitting.fit_result import FitStatus
from comanip.optim import Status
from comanip.planning.plan import PlanStatus

SOURCE = Path(__file__).resolve().parents[2] / "src" / "comanip"
STATUS_WORDS = {str(status) for enum in (Status, PlanStatus, EstimateStatus, FitStatus) for status in enum}
"""Every status's value (a solver's word such as IPOPT's 'User_Requested_Stop' is not one)."""


def _is_status(node: ast.expr) -> bool:
    """``status``, ``x.status``, ``x.solve_status`` or ``x["status"]``: something holding a status."""
    name = node.attr if isinstance(node, ast.Attribute) else node.id if isinstance(node, ast.Name) else \
        node.slice.value if isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant) else None
    return isinstance(name, str) and name.endswith("status")


def _strings(node: ast.expr) -> list[str]:
    """The status words among the string literals ``node`` is, or holds as a tuple, list or set of literals."""
    if isinstance(node, ast.Constant) and node.value in STATUS_WORDS:
        return [node.value]
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
        return [s for element in node.elts for s in _strings(element)]
    if isinstance(node, ast.IfExp):
        return _strings(node.body) + _strings(node.orelse)
    return []


def status_literals(source: str) -> list[str]:
    """Where ``source`` compares a status with a status word as a string literal (``status == "converged"``, ``x.status in ("a",
    "b")``) or sets one from a literal (``status="failed"``, ``status = "unidentified"``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(_is_status(side) for side in sides) and any(_strings(side) for side in sides):
                found.append(f"line {node.lineno}: {ast.unparse(node)}")
        elif isinstance(node, ast.keyword) and node.arg is not None and node.arg.endswith("status") and _strings(node.value):
            found.append(f"line {node.value.lineno}: {node.arg}={ast.unparse(node.value)}")
        elif isinstance(node, ast.Assign) and any(_is_status(target) for target in node.targets) and _strings(node.value):
            found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return sorted(found, key=lambda place: int(place.split(":")[0].split()[1]))


def test_no_status_is_a_string_literal_in_the_package():
    offenders = {str(path.relative_to(SOURCE)): found for path in sorted(SOURCE.rglob("*.py"))
                 if (found := status_literals(path.read_text(encoding="utf-8")))}
    assert not offenders, offenders


def test_a_status_literal_is_found():
    """The check above, tried: each way a literal stands for a status is reported; the enums' members are not."""
    source = ('if estimate.status == "uninformative":\n    pass\n'
              'ok = fit.status in ("converged", "max_evaluations")\n'
              'result = FitResult(status="failed")\n'
              'status = "converged" if done else "unidentified"\n'
              'record["status"] = "solved"\n'
              'fine = plan.status == Status.SOLVED and FitResult(status=FitStatus.FAILED) and label == "converged"\n')
    assert [found.split(":")[0] for found in status_literals(source)] == ["line 1", "line 3", "line 4", "line 5", "line 6"]
