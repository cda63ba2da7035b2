"""Functions of readable size: every function over 80 lines of code (docstring, comments
and blank lines not counted) says at the top of its docstring why it is long.

Files are split by concept, not by size: the layout rules (a folder per family, at most
15 modules a folder, no import cycles) are in ``tests/test_architecture.py``."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
FILES = sorted(SRC.rglob("*.py"))
MAX_FUNCTION_LINES = 80
#: Words that give the reason for a long function in its docstring.
REASON_WORDS = ("long because", "longer than 80", "reason for length")


def _code_lines(lines: list[str], node: ast.AST) -> int:
    skip: set[int] = set()
    first = node.body[0]  # type: ignore[attr-defined]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) \
            and isinstance(first.value.value, str):
        skip = set(range(first.lineno, first.end_lineno + 1))  # type: ignore[operator]
    return sum(1 for i in range(node.lineno, node.end_lineno + 1)  # type: ignore[attr-defined]
               if i not in skip and lines[i - 1].strip()
               and not lines[i - 1].strip().startswith("#"))


def _long_functions():
    for path in FILES:
        text = path.read_text()
        lines = text.splitlines()
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = _code_lines(lines, node)
                if n > MAX_FUNCTION_LINES:
                    yield path.relative_to(SRC).as_posix(), node, n


def test_counter_counts_code_only():
    src = 'def f():\n    """Doc\n\n    more."""\n    # comment\n\n    return 1\n'
    node = ast.parse(src).body[0]
    assert _code_lines(src.splitlines(), node) == 2         # the def line and the return


def test_long_functions_say_why():
    missing = [f"{rel}:{node.lineno} {node.name} ({n} lines)"
               for rel, node, n in _long_functions()
               if not any(w in (ast.get_docstring(node) or "").lower() for w in REASON_WORDS)]
    assert not missing, "functions over 80 lines without a reason: " + ", ".join(missing)
