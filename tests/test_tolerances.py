"""One home for numerical thresholds per core (issue 10, item 2): no float literal below
1e-4 in ``taut.sheet``, ``taut.plan``, ``taut.cdpr`` or ``taut.physics`` outside the cores'
``_tol`` modules, except named physical parameters (listed below with the reason)."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "taut"
CORES = ("sheet", "plan", "cdpr", "physics")
#: Small float literals that are not thresholds: (file, value) -> reason.
NOT_THRESHOLDS = {
    ("cdpr/control/dynamics.py", 4.5e-5): "motor rotor inertia, kg m^2 (a physical parameter)",
    ("cdpr/control/dynamics.py", 2e-5): "viscous friction coefficient (a physical parameter)",
}


def _docstrings(tree: ast.AST) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            first = node.body[0] if node.body else None
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                out.add(id(first.value))
    return out


def small_float_literals() -> list[tuple[str, int, float]]:
    """(file relative to src/taut, line, value) of every float literal 0 < |x| < 1e-4 in the
    cores outside their ``_tol`` modules (docstrings skipped)."""
    found = []
    for core in CORES:
        for path in sorted((SRC / core).glob("*.py")):
            if path.name == "_tol.py":
                continue
            tree = ast.parse(path.read_text())
            skip = _docstrings(tree)
            rel = path.relative_to(SRC).as_posix()
            for node in ast.walk(tree):
                if (isinstance(node, ast.Constant) and type(node.value) is float
                        and id(node) not in skip and 0 < abs(node.value) < 1e-4):
                    found.append((rel, node.lineno, node.value))
    return sorted(found)


def test_finder_sees_literals_and_skips_docstrings():
    tree = ast.parse('"""1e-9"""\nx = 1e-9\n')
    assert len(_docstrings(tree)) == 1


def test_thresholds_live_in_tol_modules():
    stray = [f"{rel}:{line} {value!r}" for rel, line, value in small_float_literals()
             if (rel, value) not in NOT_THRESHOLDS]
    assert not stray, ("inline thresholds (move them to the core's _tol.py with unit and "
                       "reason): " + ", ".join(stray))
