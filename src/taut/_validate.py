"""Input checks shared by every model and analysis: turn user values into float64 arrays
or raise :class:`taut.errors.InvalidInputError` naming the field."""

from __future__ import annotations

from typing import Any

import numpy as np

from .errors import InvalidInputError

__all__ = ["as_array", "as_points", "as_positive", "as_finite_scalar", "as_nonnegative",
           "check_range", "as_mass", "as_count", "as_box", "require_instance",
           "require_nonempty", "LIMITS", "require_instances", "as_tolerance", "as_path", "as_choice",
           "as_flag"]


def as_array(value: Any, field: str, *, ndim: int | None = None,
             shape: tuple[int | None, ...] | None = None) -> np.ndarray:
    """Convert ``value`` to a finite float64 array, checking its rank and shape.

    ``shape`` entries that are ``None`` accept any length on that axis.
    """
    if value is None:            # np.array(None, float) is NaN: say what is missing instead
        raise InvalidInputError(field, "must be a number or an array of numbers, got null "
                                       "(None)")
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
    if value is None:
        raise InvalidInputError(field, "must be a number, got null (None)")
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


# --- The numeric range every input accepts ----------------------------------------------------
#
# One table for the whole package (the README's "Accepted ranges" section repeats it). The
# limits keep every intermediate product of the solvers far from float64 overflow (squared
# lengths, tensions times lengths, LP coefficients) and far from sizes no machine solves; a
# value outside is a typed error, never an ``inf`` in a result or a wrong "no".

#: Largest |coordinate| of a sheet vertex, robot position, object target or hold height (any
#: length unit, e.g. mm: 1 km). FK normalises by the sheet size, so only the spread between
#: the largest and the smallest length matters; squared lengths stay <= 1e12, far from
#: overflow, and a sheet 1e6 units wide still resolves 1e-6 unit details in float64.
MAX_SHEET_LENGTH = 1e6
#: Largest |coordinate| of a cable-robot point, pose or workspace box, m (1 km; FASTKIT is 5 m).
MAX_CDPR_LENGTH_M = 1e3
#: Largest object / payload mass, kg.
MAX_MASS_KG = 1e6
#: Largest cable tension limit, N (the LP/QP and closed-form methods agree up to here).
MAX_TENSION_N = 1e9
#: Largest speed or rate limit (m/s, rad/s) and twist component.
MAX_SPEED = 1e3
#: Largest acceleration limit or acceleration, m/s^2 (10^5 g).
MAX_ACCELERATION = 1e3 * MAX_SPEED
#: Largest number of robots in a team (FK is O(N^2) hull faces; planning far less).
MAX_ROBOTS = 1000
#: Largest team inverse kinematics takes. Its joint search (SLSQP over two unknowns a
#: robot, dense) costs ~N^3 a step and holds the interpreter for the whole step, so Ctrl-C
#: waits for it. Measured (`taut ik` of a regular team, object at half the hold height,
#: load 4-10): N = 100 3.9 s; N = 200 50 s (30 s CPU, 146 MB; Ctrl-C answered 4-6 s after
#: the signal mid-search); N = 400 one step over 10 min; N = 1000 1.3-1.6 GB, unfinished
#: after 400 s.
MAX_IK_ROBOTS = 200
#: Largest number of cables of a cable robot (real CDPRs have 4 to a few tens; FASTKIT 8).
MAX_CABLES = 100
#: Largest count of numbers (candidate facets times the subset matrix and row each holds)
#: an exact wrench or twist set may build for one pose (:mod:`taut.cdpr.sets._budget`).
#: Measured (`/usr/bin/time`, peak RSS, ~0.17 GB of it start-up; CPU time loaded):
#: `taut cdpr wrench-set`, 6-DoF fixed ring of 12 cables: 16.6 million, 0.43 GB, 9-10 s;
#: the library's wrench set of a 3-DoF ring of 11 cables (37 million, now refused): 0.76 GB;
#: `taut cdpr twist-set`, 48 cables and one moving base: 27.6 million, 0.74 GB, 3 s; 10
#: cables on 4 moving bases: 28.0 million, 0.50 GB, 6.5 s. So an accepted set stays under
#: ~0.8 GB; one more cable multiplies the count by 2-6.
MAX_SET_NUMBERS = 30_000_000
#: Largest number of poses / formations / grid points in one call.
MAX_BATCH = 10_000_000
#: Most platform poses (positions x orientations) of one wrench-feasible workspace
#: (:func:`taut.cdpr.wrench_feasible_workspace`, its grid, a sweep task's grid): `taut cdpr
#: workspace fastkit --grid 1000 1 1000` at the limit peaked at 565 MB, 76 s
#: (`/usr/bin/time`, loaded).
MAX_WORKSPACE_POSES = 1_000_000
#: Most control steps of one cable-robot control simulation (``duration`` and ``settle``
#: times the control rate) and samples of a pick-and-place reference: 60 s at FASTKIT's
#: 1 kHz. Memory grows ~3.8 kB a step, ~12 kB with the JSON result (`taut cdpr simulate
#: fastkit --dwell 100`, 201,900 steps, `/usr/bin/time`, loaded: 0.91 GB; with `--out`
#: 2.45 GB, 118 s; --dwell 400 with --out 8.6 GB), so MAX_BATCH steps would need ~40 GB;
#: peak RSS with `--out` at 99,676 steps 1.32 GB, at 59,876 steps (`--dwell 29`) 0.90 GB.
MAX_CONTROL_STEPS = 60_000
#: Largest control or sampling rate, Hz (1 MHz; FASTKIT's controller runs at 1 kHz).
MAX_RATE_HZ = 1e6
#: Longest simulated or dwelt time, s (one day).
MAX_DURATION_S = 86_400.0

LIMITS: dict[str, tuple[float, str]] = {
    "sheet length": (MAX_SHEET_LENGTH, "sheet units"),
    "cable-robot length": (MAX_CDPR_LENGTH_M, "m"),
    "mass": (MAX_MASS_KG, "kg"),
    "tension": (MAX_TENSION_N, "N"),
    "speed": (MAX_SPEED, "m/s or rad/s"),
    "acceleration": (MAX_ACCELERATION, "m/s^2"),
    "robots": (MAX_ROBOTS, "robots"),
    "cables": (MAX_CABLES, "cables"),
    "batch": (MAX_BATCH, "items"),
    "control steps": (MAX_CONTROL_STEPS, "steps"),
    "rate": (MAX_RATE_HZ, "Hz"),
    "duration": (MAX_DURATION_S, "s"),
}


def as_bounded(value: Any, field: str, limit: float, unit: str, *,
               positive: bool = True) -> float:
    """A finite float in ``(0, limit]`` (``[0, limit]`` when ``positive`` is false).

    Examples
    --------
    >>> as_bounded(2.0, "speed", MAX_SPEED, "m/s")
    2.0
    >>> as_bounded(1e308, "speed", MAX_SPEED, "m/s")
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: speed: 1e+308 exceeds the accepted range 1000 m/s
    """
    x = as_positive(value, field) if positive else as_nonnegative(value, field)
    if x > limit:
        raise InvalidInputError(field, f"{x:g} exceeds the accepted range {limit:g} {unit}")
    return x


def check_range(arr: Any, field: str, limit: float, unit: str) -> np.ndarray:
    """``arr`` (as a finite float64 array) with every ``|value| <= limit``.

    Examples
    --------
    >>> check_range([1.0, -2.0], "pose", 1e3, "m").tolist()
    [1.0, -2.0]
    >>> check_range([1e308], "pose", 1e3, "m")
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: pose: |value| 1e+308 exceeds the accepted range 1000 m
    """
    a = as_array(arr, field)
    if a.size and float(np.max(np.abs(a))) > limit:
        big = float(np.max(np.abs(a)))
        raise InvalidInputError(field, f"|value| {big:g} exceeds the accepted range "
                                       f"{limit:g} {unit}")
    return a


def as_mass(value: Any, field: str = "mass") -> float:
    """A mass in kg, ``0 < m <= MAX_MASS_KG``."""
    m = as_positive(value, field)
    check_range(m, field, MAX_MASS_KG, "kg")
    return m


def as_count(value: Any, field: str, *, minimum: int = 0, maximum: int | None = None) -> int:
    """An integer (not a bool, not a float) with ``minimum <= value <= maximum``.

    Examples
    --------
    >>> as_count(3, "n", minimum=3)
    3
    >>> as_count(-1, "chunk", minimum=1)
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: chunk: must be an integer >= 1, got -1
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidInputError(field, f"must be an integer, got {value!r}")
    n = int(value)
    if n < minimum:
        raise InvalidInputError(field, f"must be an integer >= {minimum}, got {n}")
    if maximum is not None and n > maximum:
        raise InvalidInputError(field, f"must be at most {maximum}, got {n} (the accepted "
                                       "range bounds the work)")
    return n


def as_box(value: Any, field: str, *, limit: float = MAX_CDPR_LENGTH_M, unit: str = "m",
           allow_flat: bool = True) -> np.ndarray:
    """An axis-aligned box given as ``xmin xmax ymin ymax zmin zmax`` (the one order every
    ``taut`` option uses) or as ``[[xmin, ymin, zmin], [xmax, ymax, zmax]]``; returns the
    (2, 3) corner form.

    A box with some ``max < min`` is an error; ``max == min`` (a slice) is accepted when
    ``allow_flat``.

    Examples
    --------
    >>> as_box([-1, 1, 0, 0, 0.2, 2], "--box").tolist()
    [[-1.0, 0.0, 0.2], [1.0, 0.0, 2.0]]
    >>> as_box([1, -1, 0, 0, 0, 1], "--box")
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: --box: xmax -1 < xmin 1 (give XMIN XMAX YMIN YMAX ZMIN ZMAX)
    """
    b = check_range(value, field, limit, unit)
    if b.shape == (6,):
        b = b.reshape(3, 2).T
    if b.shape != (2, 3):
        raise InvalidInputError(field, "must be XMIN XMAX YMIN YMAX ZMIN ZMAX")
    bad = b[1] < b[0] if allow_flat else b[1] <= b[0]
    if np.any(bad):
        k = int(np.argmax(bad))
        a = "xyz"[k]
        rel = "<" if allow_flat else "<="
        raise InvalidInputError(field, f"{a}max {b[1, k]:g} {rel} {a}min {b[0, k]:g} (give "
                                       "XMIN XMAX YMIN YMAX ZMIN ZMAX)")
    return b


def _type_name(cls: type) -> str:
    """``taut.cdpr.model.robot.CableRobot`` -> ``taut.cdpr.model.robot.CableRobot`` (private modules'
    leading underscores dropped), builtins by their bare name."""
    if cls.__module__ == "builtins":
        return cls.__name__
    return f"{cls.__module__.replace('._', '.')}.{cls.__name__}"


def require_instance(value: Any, cls: type | tuple[type, ...], field: str) -> Any:
    """``value`` if it is an instance of ``cls`` (a type or a tuple of types), else an error
    naming the expected type (so ``None`` in place of a model is a typed error, not an
    ``AttributeError``).

    Examples
    --------
    >>> require_instance(None, int, "robot")
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: robot: must be a int, got NoneType
    """
    classes = cls if isinstance(cls, tuple) else (cls,)
    if not isinstance(value, classes) or (isinstance(value, bool) and bool not in classes
                                          and int in classes):
        want = " or ".join(_type_name(c) for c in classes)
        raise InvalidInputError(field, f"must be a {want}, got {type(value).__name__}")
    return value


def require_instances(values: Any, cls: type, field: str, *, min_count: int = 0) -> tuple:
    """``values`` as a tuple whose every item is a ``cls`` (at least ``min_count``), else an
    error naming the item (``bases[1]: must be a ...Base, got str``)."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise InvalidInputError(field, f"must be a sequence of {_type_name(cls)}, got "
                                       f"{type(values).__name__}")
    items = tuple(values)
    for k, v in enumerate(items):
        require_instance(v, cls, f"{field}[{k}]")
    if len(items) < min_count:
        raise InvalidInputError(field, f"needs at least {min_count} item(s), got {len(items)}")
    return items


def as_tolerance(value: Any, field: str) -> float:
    """A tolerance or margin: a finite float in ``[0, 1e6]`` (any unit; larger is no longer a
    tolerance and would make every comparison true)."""
    return as_bounded(value, field, 1e6, "units", positive=False)


def require_nonempty(arr: np.ndarray, field: str) -> np.ndarray:
    """``arr`` unless it has a zero-length axis (an empty batch or point list)."""
    if arr.size == 0:
        raise InvalidInputError(field, f"is empty (shape {'x'.join(map(str, arr.shape))})")
    return arr


def as_path(value: Any, field: str = "path") -> Any:
    """``value`` as a :class:`pathlib.Path` if it is a non-empty ``str`` or path-like, else
    an error (``None`` or a number in place of a file name).

    Examples
    --------
    >>> as_path(None)
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: path: must be a file name (str or path), got NoneType
    """
    import os
    from pathlib import Path
    if isinstance(value, bool) or not isinstance(value, (str, os.PathLike)):
        raise InvalidInputError(field, f"must be a file name (str or path), got "
                                       f"{type(value).__name__}")
    if str(value) == "":
        raise InvalidInputError(field, "is empty")
    return Path(value)


def as_choice(value: Any, choices: Any, field: str) -> str:
    """``value`` if it is one of the strings ``choices``, else an error listing them (a
    non-string, e.g. an array, is an error rather than an ambiguous comparison).

    Examples
    --------
    >>> as_choice("task", ("task", "navigation"), "mode")
    'task'
    >>> as_choice(3, ("task", "navigation"), "mode")
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: mode: unknown mode 3; choose one of task, navigation
    """
    if not isinstance(value, str) or value not in tuple(choices):
        raise InvalidInputError(field, f"unknown {field} {value!r}; choose one of "
                                       + ", ".join(map(str, choices)))
    return value


def as_flag(value: Any, field: str) -> bool:
    """``value`` as a Python bool if it is a ``bool`` or a numpy bool, else an error (an
    array or a string in place of a switch is not silently truthy or ambiguous).

    Examples
    --------
    >>> as_flag(True, "tipping")
    True
    >>> as_flag("no", "tipping")
    Traceback (most recent call last):
    ...
    taut.errors.InvalidInputError: tipping: must be True or False, got str
    """
    if not isinstance(value, (bool, np.bool_)):
        raise InvalidInputError(field, f"must be True or False, got {type(value).__name__}")
    return bool(value)
