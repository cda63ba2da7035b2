"""Short reprs for taut's result and model dataclasses: one line, or a few, like scipy's
results, instead of dozens of lines of arrays.

A dataclass declared ``@dataclass(frozen=True, repr=False)`` that inherits
:class:`CompactRepr` prints ``success``, ``status`` and ``message`` first (when it has
them), then every other field that the dataclass shows in its repr: scalars and strings as
they are (long strings cut), arrays of more than :data:`INLINE_SIZE` elements as their shape
in angle brackets (with the dtype unless float64, taut's only float type), sequences as their length, nested objects by their type name.

Examples
--------
>>> from dataclasses import dataclass
>>> import numpy as np
>>> @dataclass(frozen=True, repr=False)
... class Demo(CompactRepr):
...     success: bool
...     status: str
...     tensions: np.ndarray
>>> Demo(True, "ok", np.zeros((100, 8)))
Demo(success=True, status='ok', tensions=<(100, 8)>)
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

__all__ = ["CompactRepr", "compact_repr", "short_value"]

#: Arrays with at most this many elements are printed inline.
INLINE_SIZE = 3
#: Strings (e.g. messages) longer than this are cut, with an ellipsis.
MAX_TEXT = 80
#: A repr longer than this is wrapped, one line per group of fields.
LINE_WIDTH = 92
#: Fields shown first, in this order, when a class has them.
FIRST = ("success", "status", "message")


def short_value(value: Any) -> str:
    """One short text for a field's value (see the module docstring)."""
    if isinstance(value, np.ndarray):
        if value.size <= INLINE_SIZE and value.dtype.kind in "biuf":
            return "[" + ", ".join(short_value(v) for v in value.ravel()) + "]"
        shape = f"({', '.join(str(n) for n in value.shape)}{',' if value.ndim == 1 else ''})"
        if value.dtype == np.float64:
            return f"<{shape}>"
        return f"<{shape} {'str' if value.dtype.kind in 'US' else value.dtype.name}>"
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, str):
        text = value if len(value) <= MAX_TEXT else value[:MAX_TEXT - 3] + "..."
        return repr(text)
    if isinstance(value, float):
        return f"{value:.6g}"
    if value is None or isinstance(value, (bool, int)):
        return repr(value)
    if isinstance(value, (list, tuple)):
        if len(value) <= INLINE_SIZE and all(isinstance(v, (bool, int, float, str))
                                             for v in value):
            return repr(value)
        return f"<{type(value).__name__} of {len(value)}>"
    if isinstance(value, dict):
        return f"<dict of {len(value)}>"
    return f"<{type(value).__name__}>"


def _fields(obj: Any) -> list[str]:
    # A class whose fields are computed on first access (not a dataclass) names them.
    names = list(getattr(obj, "REPR_FIELDS", ())) or [f.name for f in dataclasses.fields(obj)
                                                       if f.repr]
    return [n for n in FIRST if n in names] + [n for n in names if n not in FIRST]


def compact_repr(obj: Any) -> str:
    """``Name(field=value, ...)`` of a dataclass instance, wrapped at :data:`LINE_WIDTH`."""
    name = type(obj).__name__
    parts = [f"{n}={short_value(getattr(obj, n))}" for n in _fields(obj)]
    one = f"{name}({', '.join(parts)})"
    if len(one) <= LINE_WIDTH:
        return one
    lines, line = [], f"{name}("
    for i, part in enumerate(parts):
        piece = part + (", " if i < len(parts) - 1 else ")")
        if len(line) + len(piece) > LINE_WIDTH and line.strip() != f"{name}(":
            lines.append(line.rstrip())
            line = " " * (len(name) + 1)
        line += piece
    lines.append(line)
    return "\n".join(lines)


class CompactRepr:
    """Mixin giving a dataclass (declared with ``repr=False``) :func:`compact_repr`; a
    class that is not a dataclass lists its fields in a ``REPR_FIELDS`` tuple."""

    __slots__ = ()

    def __repr__(self) -> str:
        return compact_repr(self)
