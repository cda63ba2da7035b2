"""The batching rule of taut's pose analyses (private helpers).

Single in -> single out, batch in -> batch out (like numpy and shapely 2.x): a pose of
shape ``(6,)`` or ``(3,)`` gives an unbatched result (``success`` a ``bool``, ``status`` a
``str``, per-cable arrays of shape ``(m,)``); poses of shape ``(B, 6)`` or ``(B, 3)`` give
arrays with a leading axis of length B, even for ``B = 1``. The analyses compute on the
batched form and drop the leading axis at the end with :func:`unbatch`.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")


def is_single(poses: Any) -> bool:
    """Whether ``poses`` is one pose (a 1-D array_like) rather than a batch. Malformed
    input (ragged lists, ...) counts as a batch: the validator then names the problem."""
    try:
        return bool(np.ndim(poses) == 1)
    except (ValueError, TypeError):
        return False


def first(value: Any) -> Any:
    """``value[0]`` with numpy bools and strings turned into ``bool`` and ``str``."""
    v = value[0]
    if isinstance(v, np.bool_):
        return bool(v)
    if isinstance(v, np.str_):
        return str(v)
    return v


def unbatch(result: T, fields: tuple[str, ...], single: bool) -> T:
    """``result`` with the leading (pose) axis of ``fields`` dropped when ``single``."""
    if not single:
        return result
    return dataclasses.replace(result, **{f: first(getattr(result, f))  # type: ignore
                                          for f in fields})
