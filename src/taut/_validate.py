"""Input checks shared by every model and analysis: turn user values into float64 arrays
or raise :class:`taut.errors.InvalidInputError` naming the field."""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import InvalidInputError

__all__ = ["as_array", "as_points", "as_positive", "as_finite_scalar", "as_nonnegative"]


def as_array(value: Any, field: str, *, ndim: int | None = None,
             shape: tuple[int | None, ...] | None = None) -> np.ndarray:
    """Convert ``value`` to a finite float64 array, checking its rank and shape.

    ``shape`` entries that are ``None`` accept any length on that axis.
    """
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(field, "must be numeric (a list or array of numbers)") from None
    if shape is not None:
        ndim = len(shape)
    if ndim is not None and arr.ndim != ndim:
        want = "x".join("N" if s is None else str(s) for s in shape) if shape else f"{ndim}-D"
        raise InvalidInputError(field, f"must have shape {want}, got shape "
                                       f"{'x'.join(map(str, arr.shape)) or 'scalar'}")
    if shape is not None:
        for axis, want_len in enumerate(shape):
            if want_len is not None and arr.shape[axis] != want_len:
                want = "x".join("N" if s is None else str(s) for s in shape)
                raise InvalidInputError(field, f"must have shape {want}, got shape "
                                               f"{'x'.join(map(str, arr.shape))}")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(field, "contains NaN or infinite values")
    return arr


def as_points(value: Any, field: str, *, dim: int = 2, min_count: int = 1) -> np.ndarray:
    """An ``(n, dim)`` float64 array of finite points with ``n >= min_count``."""
    arr = as_array(value, field, shape=(None, dim))
    if arr.shape[0] < min_count:
        raise InvalidInputError(field, f"needs at least {min_count} points, got {arr.shape[0]}")
    return arr


def as_finite_scalar(value: Any, field: str) -> float:
    """A finite Python float."""
    if isinstance(value, bool):
        raise InvalidInputError(field, "must be a number, got a boolean")
    arr = as_array(value, field)
    if arr.ndim != 0:
        raise InvalidInputError(field, "must be a single number")
    return float(arr)


def as_positive(value: Any, field: str) -> float:
    """A finite float > 0."""
    x = as_finite_scalar(value, field)
    if not x > 0.0:
        raise InvalidInputError(field, f"must be positive, got {x:g}")
    return x


def as_nonnegative(value: Any, field: str) -> float:
    """A finite float >= 0."""
    x = as_finite_scalar(value, field)
    if not x >= 0.0:
        raise InvalidInputError(field, f"must be non-negative, got {x:g}")
    return x
