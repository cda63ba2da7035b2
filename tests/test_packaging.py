"""The package's metadata: licences declared and shipped (PEP 639)."""

from __future__ import annotations

from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")      # Python >= 3.11

ROOT = Path(__file__).resolve().parents[1]


def _project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_every_declared_licence_file_exists():
    files = _project()["project"]["license-files"]
    assert files, "no licence file declared"
    for name in files:
        assert (ROOT / name).is_file(), name


def test_every_licence_file_in_the_package_is_declared():
    """Vendored code (the app's Plotly.js) brings its licence: it must travel in the wheel's
    metadata, and its licence must be part of the declared expression."""
    declared = {str(Path(p)) for p in _project()["project"]["license-files"]}
    shipped = {str(p.relative_to(ROOT)) for p in (ROOT / "src" / "taut").rglob("*")
               if p.is_file() and "licen" in p.name.lower()}
    assert shipped <= declared, shipped - declared


def test_licence_is_an_spdx_expression_with_a_backend_that_reads_it():
    project = _project()
    assert isinstance(project["project"]["license"], str)      # not the deprecated table
    assert "BSD-3-Clause" in project["project"]["license"]
    requires = project["build-system"]["requires"]
    assert any(r.replace(" ", "").startswith("setuptools>=") and
               tuple(int(x) for x in r.split(">=")[1].split(".")[:1]) >= (77,)
               for r in requires), requires
