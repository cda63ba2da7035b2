"""Reading YAML/JSON files into plain mappings, and pydantic validation with errors that
name the offending field. Every loader in :mod:`taut.io` goes through these two functions."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from ..errors import ScenarioError

__all__ = ["read_text", "read_mapping", "validate_mapping", "write_json"]

M = TypeVar("M", bound=BaseModel)


def read_text(path: str | Path) -> str:
    """The UTF-8 text of a file; a missing or unreadable file is a :class:`ScenarioError`
    naming the path."""
    p = Path(path)
    if not p.is_file():
        raise ScenarioError(str(path), "file not found")
    try:
        return p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(str(path), f"cannot read file ({exc.__class__.__name__})") from None


def read_mapping(path: str | Path) -> dict[str, Any]:
    """Parse a ``.yaml``/``.yml``/``.json`` file whose top level is a mapping.

    Raises
    ------
    ScenarioError
        Missing or unreadable file, a syntax error, or a top level that is not a mapping.
    """
    p = Path(path)
    text = read_text(p)
    try:
        if p.suffix.lower() == ".json":
            data = json.loads(text)
        else:
            data = yaml.safe_load(text)
    except json.JSONDecodeError as exc:
        raise ScenarioError(str(path), f"invalid JSON at line {exc.lineno}: {exc.msg}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark is not None else ""
        raise ScenarioError(str(path), f"invalid YAML{where}") from None
    if not isinstance(data, dict):
        raise ScenarioError(str(path), "top level must be a mapping of keys to values")
    return data


def _location(loc: tuple[Any, ...]) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out or "(top level)"


def validate_mapping(model: type[M], data: dict[str, Any]) -> M:
    """Validate ``data`` against a pydantic model; the first error becomes a
    :class:`ScenarioError` whose field is the dotted path (``sheet[2]``, ``cables[0].max``)."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = _location(tuple(p for p in err["loc"] if not (isinstance(p, str) and "[" in p)))
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        elif err["type"] == "missing":
            msg = "required key is missing"
        raise ScenarioError(loc, msg[0].lower() + msg[1:]) from None


def write_json(obj: Any, path: str | Path) -> None:
    """Write ``obj`` as indented JSON."""
    Path(path).write_text(json.dumps(obj, indent=2) + "\n", encoding="utf-8")
