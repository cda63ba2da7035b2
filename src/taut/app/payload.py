"""Reading the JSON bodies the page sends, and turning uploaded or bundled files into
validated models with the same loaders (and so the same one-line errors) as the CLI.

Every failure is a :class:`taut.errors.TautError`; the server turns it into
``{"error": "<field>: <problem>"}``, exactly what ``taut`` prints after ``taut: error:``.
"""

from __future__ import annotations

import json
import tempfile
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from ..errors import InvalidInputError, ScenarioError, TautError
from ..io import read_mapping

__all__ = ["field", "mapping_from_upload", "ModelCache", "kind_of_mapping"]

T = TypeVar("T")

_MISSING = object()


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


def mapping_from_upload(text: str, filename: str) -> dict[str, Any]:
    """Parse uploaded file text exactly as the CLI parses a file of that name.

    The text is written to a private temporary folder under the upload's base name and
    read with :func:`taut.io.read_mapping`, so a syntax error reads
    ``<name>: invalid YAML at line 3`` as in the CLI (without the temporary folder).

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
    name = Path(filename or "upload.yaml").name or "upload.yaml"
    with tempfile.TemporaryDirectory(prefix="taut-app-") as tmp:
        path = Path(tmp) / name
        path.write_text(text, encoding="utf-8")
        try:
            return read_mapping(path)
        except TautError as exc:
            raise ScenarioError(exc.field.replace(str(path), name), exc.problem) from None


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

