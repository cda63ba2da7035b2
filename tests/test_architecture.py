"""The package's layout is its architecture: a folder per family, one front end per package,
no import cycles, an API map in each package docstring, nothing kept for compatibility.

The import graph is read from the source (``ast``), so these rules hold without importing
anything. Imports under ``if TYPE_CHECKING:`` do not count (they never run)."""

from __future__ import annotations

import ast
import functools
import importlib
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = SRC / "taut"
#: Most modules of its own (``__init__.py`` not counted) a package folder may hold.
MAX_MODULES_PER_FOLDER = 15
#: Packages whose public names must all appear in their package docstring.
MAPPED = ("taut.sheet", "taut.plan", "taut.cdpr")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _runtime_imports(tree: ast.AST):
    """Import nodes that can run (not under ``if TYPE_CHECKING:``)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and _is_type_checking(child.test):
                stack.extend(child.orelse)
                continue
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                yield child
            stack.append(child)


def _targets(name: str, path: Path) -> set[str]:
    """The taut modules a module imports (a name imported from a package that is itself a
    module counts as that module)."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out: set[str] = set()
    for node in _runtime_imports(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name in MODULES)
            continue
        if node.level:
            base = package.split(".")[: len(package.split(".")) - node.level + 1]
            target = ".".join(base + ([node.module] if node.module else []))
        else:
            target = node.module or ""
        if target not in MODULES:
            continue
        subs = {f"{target}.{a.name}" for a in node.names} & MODULES.keys()
        out.update(subs)
        if len(subs) < len(node.names):
            out.add(target)
    out.discard(name)
    return out


@functools.lru_cache(maxsize=None)
def _graph() -> dict[str, set[str]]:
    """Module -> the taut modules it imports; built when a test first asks (parsing every
    module takes about a second of CPU, which each test process would otherwise pay when it
    collects this file)."""
    return {name: _targets(name, path) for name, path in MODULES.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    edges = graph
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def test_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"p": {"p.x"}, "p.x": {"q"}, "q": set()}) == []


def test_no_import_cycles():
    assert _cycles(_graph()) == []


#: Modules at the package root that drive the families (the command line, the warmup that
#: runs their entry points) rather than serve them.
ROOT_DRIVERS = {"taut.__main__", "taut._warmup"}


def _family_imports(name: str) -> set[str]:
    """The modules of family folders (``taut.sheet``, ``taut.cdpr``, ...) ``name`` imports."""
    return {t for t in _graph()[name] if t.count(".") >= 1
            and (PACKAGE / t.split(".")[1]).is_dir()}


def test_shared_root_modules_import_no_family():
    """The other root modules are shared by the families (validation, errors, the compiled
    kernels' set-up, the QP solver, the one convex hull of ``taut._geometry`` that the
    planner's kernels and the cable robots both use): a family imported there would tie
    every family that shares the module to it."""
    root = [n for n, p in MODULES.items() if p.parent == PACKAGE and p.name != "__init__.py"]
    assert "taut._geometry" in root and ROOT_DRIVERS <= set(root)
    assert {n: _family_imports(n) for n in root if n not in ROOT_DRIVERS and
            _family_imports(n)} == {}
    assert all(_family_imports(n) for n in ROOT_DRIVERS)     # the exception is needed


def test_folders_hold_few_modules():
    crowded = {}
    for folder in sorted({p.parent for p in MODULES.values()}):
        own = [p for p in folder.glob("*.py") if p.name != "__init__.py"]
        if len(own) > MAX_MODULES_PER_FOLDER:
            crowded[folder.relative_to(SRC).as_posix()] = len(own)
    assert crowded == {}


def test_every_folder_is_a_package():
    for folder in {p.parent for p in PACKAGE.rglob("*.py")}:
        assert (folder / "__init__.py").exists(), folder


def test_one_grouped_all():
    for name, path in MODULES.items():
        text = path.read_text()
        assert "__all__ +=" not in text, f"{name}: one grouped __all__"
        assert text.count("__all__ =") <= 1, name


@pytest.mark.parametrize("package", MAPPED)
def test_package_docstring_maps_every_public_name(package):
    mod = importlib.import_module(package)
    doc = mod.__doc__ or ""
    missing = [n for n in mod.__all__ if not re.search(rf"(?<![\w.]){re.escape(n)}(?!\w)", doc)]
    assert missing == [], f"{package} docstring does not name {missing}"
    assert len(set(mod.__all__)) == len(mod.__all__), "a name listed twice in __all__"


@pytest.mark.parametrize("package", MAPPED)
def test_subpackages_are_not_second_front_ends(package):
    """The public import path is the package; its sub-folders hold no re-exports."""
    root = PACKAGE / package.split(".")[1]
    for init in root.rglob("__init__.py"):
        if init.parent == root:
            continue
        tree = ast.parse(init.read_text())
        assert not [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))], init


def test_nothing_kept_for_compatibility():
    pattern = re.compile(r"deprecated_alias|renamed_keyword|DeprecationWarning|_MOVED\b")
    hits = [f"{name}" for name, path in MODULES.items() if pattern.search(path.read_text())]
    assert hits == []
