"""The README's Python snippets run as written, in order, in one namespace (as a reader
would paste them into one session). Snippets that run a search of a minute or more
(planning, deployment) are marked slow."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

README = Path(__file__).parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
SLOW = ("plan(", "plan_deployment(")
NAMESPACE: dict = {}


def test_readme_has_snippets():
    assert len(BLOCKS) >= 5


@pytest.mark.parametrize("k", [
    pytest.param(k, marks=pytest.mark.slow) if any(s in b for s in SLOW) else k
    for k, b in enumerate(BLOCKS)])
def test_readme_snippet_runs(k, monkeypatch):
    monkeypatch.chdir(README.parent)
    code = compile(BLOCKS[k], f"README.md python block {k + 1}", "exec")
    exec(code, NAMESPACE)                                   # noqa: S102 (our own README)
