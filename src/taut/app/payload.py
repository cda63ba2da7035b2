"""Reading the JSON bodies the page sends, and turning uploaded or bundled files into
validated models with the same loaders (and so the same one-line errors) as the CLI.

Every failure is a :class:`taut.errors.TautError`; the server turns it into
``{"error": "<field>: <problem>"}``, exactly what ``taut`` prints after ``taut: error:``.
"""

from __future__ import annotations

import json
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from ..errors import InvalidInputError, ScenarioError, TautError
from ..io import parse_mapping

__all__ = ["field", "numbers", "check_json", "check_filename", "mapping_from_upload",
           "ModelCache", "kind_of_mapping", "MAX_DEPTH"]

T = TypeVar("T")

_MISSING = object()

#: Deepest nesting of lists and objects accepted in a request body (a drag path is 4).
MAX_DEPTH = 32
#: Longest upload file name, characters.
MAX_NAME = 255


def _bad_constant(name: str) -> Any:
    raise InvalidInputError("request", f"{name} is not a JSON number")


def check_json(raw: bytes) -> dict[str, Any]:
    """Decode a request body: UTF-8 JSON, a top-level object, nested at most
    :data:`MAX_DEPTH` deep, no NaN/Infinity, every string valid Unicode.

    Raises
    ------
    InvalidInputError
        ``request`` (not JSON, not an object, too deep) or the top-level key whose value
        holds a lone surrogate (``"\\ud800"`` decodes to text that is not Unicode).

    Examples
    --------
    >>> check_json(b'{"a": [1, 2]}')
    {'a': [1, 2]}
    >>> try:
    ...     check_json(b'{"name": "\\\\ud800"}')
    ... except InvalidInputError as exc:
    ...     print(exc)
    name: is not valid Unicode (a lone surrogate)
    """
    try:
        text = raw.decode("utf-8") if raw else "{}"
    except UnicodeDecodeError:
        raise InvalidInputError("request", "is not UTF-8 text") from None
    try:
        body = json.loads(text, parse_constant=_bad_constant)
    except RecursionError:
        raise InvalidInputError("request", f"nested deeper than {MAX_DEPTH} levels") from None
    except ValueError as exc:
        if isinstance(exc, InvalidInputError):
            raise
        raise InvalidInputError("request", "is not valid JSON") from None
    if not isinstance(body, dict):
        raise InvalidInputError("request", "must be a JSON object")
    # The stack holds containers only (never one entry per number), so a body of
    # millions of numbers is walked in the memory json.loads already took.
    stack: list[tuple[Any, str, int]] = [(body, "request", 0)]
    while stack:
        value, top, depth = stack.pop()
        if depth >= MAX_DEPTH:
            raise InvalidInputError("request", f"nested deeper than {MAX_DEPTH} levels")
        entries = (((k, k if depth == 0 else top, v) for k, v in value.items())
                   if isinstance(value, dict) else ((None, top, v) for v in value))
        for key, where, v in entries:
            if key is not None:
                _unicode(key, where)
            if isinstance(v, (dict, list)):
                stack.append((v, where, depth + 1))
            elif isinstance(v, str):
                _unicode(v, where)
    return body


def _unicode(text: str, where: str) -> None:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        name = where.encode("utf-8", "replace").decode("utf-8")
        raise InvalidInputError(name, "is not valid Unicode (a lone surrogate)") from None


def field(body: dict[str, Any], name: str, kind: type | tuple[type, ...], *,
          default: Any = _MISSING) -> Any:
    """``body[name]`` checked to be of ``kind`` (a missing optional key gives ``default``).

    Raises
    ------
    InvalidInputError
        The key is missing (and has no default) or holds the wrong kind of value.
    """
    if not isinstance(body, dict):
        raise InvalidInputError("request", "must be a JSON object")
    if name not in body or body[name] is None:
        if default is _MISSING:
            raise InvalidInputError(name, "required key is missing")
        return default
    value = body[name]
    kinds = kind if isinstance(kind, tuple) else (kind,)
    if isinstance(value, bool) and bool not in kinds:
        raise InvalidInputError(name, "must not be a boolean")
    if not isinstance(value, kinds):
        names = " or ".join(k.__name__ for k in kinds)
        raise InvalidInputError(name, f"must be a {names}")
    return value


def numbers(value: Any, name: str, ndim: int, *, length: int | None = None) -> np.ndarray:
    """A JSON value as a float64 array of ``ndim`` dimensions (``length`` entries along
    the first when given).

    Raises
    ------
    InvalidInputError
        ``name``: not a (regular, nested) list of numbers of that shape; strings,
        booleans, objects and ragged lists included.

    Examples
    --------
    >>> numbers([[0, 1], [2, 3.5]], "sheet", 2).shape
    (2, 2)
    >>> try:
    ...     numbers(["a", "b"], "pose", 1)
    ... except InvalidInputError as exc:
    ...     print(exc)
    pose: must be a list of numbers
    """
    what = ("a list of numbers" if ndim == 1 else
            f"a list of {'lists of ' * (ndim - 1)}numbers")
    # Depth-first with one iterator per level, never one entry per number, so millions
    # of numbers are checked in no memory beyond the parsed JSON's.
    levels = [iter((value,))]
    while levels:
        depth = len(levels) - 1                # of the items levels[-1] yields
        for v in levels[-1]:
            if not isinstance(v, list):
                raise InvalidInputError(name, f"must be {what}")
            if depth + 1 < ndim:
                levels.append(iter(v))
                break
            if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
                raise InvalidInputError(name, f"must be {what}")
        else:
            levels.pop()
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InvalidInputError(name, f"must be {what} (rows of equal length)") from None
    if arr.ndim != ndim:
        raise InvalidInputError(name, f"must be {what} (rows of equal length)")
    if length is not None and arr.shape[0] != length:
        raise InvalidInputError(name, f"must hold {length} numbers, got {arr.shape[0]}")
    return arr


def check_filename(name: Any) -> str:
    """An upload's file name: a plain name (no folder, ``.``/``..``, NUL or control
    character), at most :data:`MAX_NAME` characters.

    Raises
    ------
    InvalidInputError
        ``filename``: anything else.
    """
    if not isinstance(name, str) or not name:
        raise InvalidInputError("filename", "must be a non-empty file name")
    if len(name) > MAX_NAME:
        raise InvalidInputError("filename", f"longer than {MAX_NAME} characters")
    if any(c in name for c in "/\\") or name in (".", ".."):
        raise InvalidInputError("filename", "must be a file name, not a path")
    if any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise InvalidInputError("filename", "must not hold control characters (NUL, "
                                            "newline, ...)")
    _unicode(name, "filename")
    return name


def mapping_from_upload(text: str, filename: str) -> dict[str, Any]:
    """Parse uploaded file text exactly as the CLI parses a file of that name
    (:func:`taut.io.parse_mapping`: size limit, alias bombs refused, JSON for ``.json``,
    YAML otherwise), so a syntax error reads ``<name>: invalid YAML at line 3``.

    Examples
    --------
    >>> mapping_from_upload("hold_height: 1\\n", "a.yaml")
    {'hold_height': 1}
    >>> try:
    ...     mapping_from_upload("[1, 2", "b.json")
    ... except TautError as exc:
    ...     print(exc)
    b.json: invalid JSON at line 1: Expecting ',' delimiter
    """
    name = check_filename(filename or "upload.yaml")
    _unicode(text, "text")
    return parse_mapping(text, name, suffix=Path(name).suffix)


def kind_of_mapping(data: dict[str, Any]) -> str:
    """Which view a scenario mapping belongs to: ``"plan"`` (has ``free_space``),
    ``"cdpr"`` (has ``cables``) or ``"sheet"``.

    >>> kind_of_mapping({"free_space": []}), kind_of_mapping({"cables": []})
    ('plan', 'cdpr')
    """
    if "free_space" in data:
        return "plan"
    if "cables" in data:
        return "cdpr"
    return "sheet"


class ModelCache:
    """Validated models keyed by their mapping, so repeated requests (every drag) reuse
    one immutable model object and the solvers' per-model precomputation.

    Parameters
    ----------
    build : callable
        Mapping -> model (raises :class:`TautError` on bad input; failures are not cached).
    size : int
        Most models kept (least recently used dropped first).
    """

    def __init__(self, build: Callable[[Any], T], size: int = 32) -> None:
        self._build = build
        self._size = size
        self._items: OrderedDict[str, Any] = OrderedDict()

    def get(self, data: Any) -> Any:
        """The model for ``data`` (built on first use)."""
        try:
            key = json.dumps(data, sort_keys=True)
        except (TypeError, ValueError):
            raise InvalidInputError("scenario", "must be plain JSON data") from None
        if key in self._items:
            self._items.move_to_end(key)
            return self._items[key]
        model = self._build(data)
        self._items[key] = model
        if len(self._items) > self._size:
            self._items.popitem(last=False)
        return model

