"""Reading YAML/JSON files into plain mappings, and pydantic validation with errors that
name the offending field. Every loader in :mod:`taut.io` goes through these two functions.

Two silent conversions are refused: a key given twice in one mapping (YAML and JSON
parsers keep the last value) and a boolean where a number is expected (pydantic's lax
mode reads ``hold_height: true`` as 1).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from ..errors import InvalidInputError, ScenarioError
from .._validate import as_path, require_instance

__all__ = ["read_text", "read_mapping", "validate_mapping", "write_json"]

M = TypeVar("M", bound=BaseModel)


def read_text(path: str | Path) -> str:
    """The UTF-8 text of a file; a missing or unreadable file is a :class:`ScenarioError`
    naming the path."""
    path = as_path(path)
    p = Path(path)
    if not p.is_file():
        raise ScenarioError(str(path), "file not found")
    try:
        return p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(str(path), f"cannot read file ({exc.__class__.__name__})") from None


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing a key that appears twice in one mapping."""


def _construct_unique_mapping(loader: yaml.SafeLoader, node: yaml.MappingNode,
                              deep: bool = False) -> dict[Any, Any]:
    seen: dict[Any, int] = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=True)
        if key in seen:
            raise ScenarioError(str(key), f"duplicate key (lines {seen[key]} and "
                                          f"{key_node.start_mark.line + 1})")
        seen[key] = key_node.start_mark.line + 1
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
                                 _construct_unique_mapping)


def _unique_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ScenarioError(key, "duplicate key")
        out[key] = value
    return out


def read_mapping(path: str | Path) -> dict[str, Any]:
    """Parse a ``.yaml``/``.yml``/``.json`` file whose top level is a mapping.

    Raises
    ------
    ScenarioError
        Missing or unreadable file, a syntax error, a key given twice, or a top level that
        is not a mapping.
    """
    path = as_path(path)
    p = Path(path)
    text = read_text(p)
    try:
        if p.suffix.lower() == ".json":
            data = json.loads(text, object_pairs_hook=_unique_pairs)
        else:
            data = yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 (a SafeLoader)
    except json.JSONDecodeError as exc:
        raise ScenarioError(str(path), f"invalid JSON at line {exc.lineno}: {exc.msg}") from None
    except RecursionError:
        raise ScenarioError(str(path), "nested too deeply") from None
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


def _booleans(data: Any, loc: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Locations of every boolean value in parsed file data."""
    if isinstance(data, bool):
        return [loc]
    if isinstance(data, dict):
        return [p for k, v in data.items() for p in _booleans(v, loc + (k,))]
    if isinstance(data, list):
        return [p for k, v in enumerate(data) for p in _booleans(v, loc + (k,))]
    return []


def _at(obj: Any, loc: tuple[Any, ...]) -> Any:
    """The validated value at ``loc`` (attribute, key or index steps), or ``_NOT_FOUND``."""
    for part in loc:
        try:
            if isinstance(part, int) or isinstance(obj, dict):
                obj = obj[part]
            else:
                obj = getattr(obj, str(part))
        except (KeyError, IndexError, AttributeError, TypeError):
            return _NOT_FOUND
    return obj


_NOT_FOUND = object()


def validate_mapping(model: type[M], data: dict[str, Any]) -> M:
    """Validate ``data`` against a pydantic model; the first error becomes a
    :class:`ScenarioError` whose field is the dotted path (``sheet[2]``, ``cables[0].max``).

    A boolean in the file that the model turned into a number is an error too (pydantic's
    lax mode accepts ``true`` for a float); booleans kept as booleans are fine."""
    if not (isinstance(model, type) and issubclass(model, BaseModel)):
        raise ScenarioError("model", "must be a pydantic model class")
    require_instance(data, dict, "data")
    try:
        validated = model.model_validate(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = _location(tuple(p for p in err["loc"] if not (isinstance(p, str) and "[" in p)))
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        elif err["type"] == "missing":
            msg = "required key is missing"
        raise ScenarioError(loc, msg[0].lower() + msg[1:]) from None
    for where in _booleans(data):
        value = _at(validated, where)
        if value is not _NOT_FOUND and not isinstance(value, bool) \
                and isinstance(value, (int, float)):
            raise ScenarioError(_location(where), "must be a number, got a boolean")
    return validated


def write_json(obj: Any, path: str | Path) -> None:
    """Write ``obj`` as indented, valid JSON (non-finite numbers become ``null``)."""
    path = as_path(path)
    from .serialize import to_json

    try:
        text = to_json(obj)
    except (TypeError, ValueError, RecursionError) as exc:
        raise InvalidInputError("obj", f"is not plain JSON data ({exc})") from None
    Path(path).write_text(text + "\n", encoding="utf-8")
