"""Robot trajectories as CSV files: one row per time step, ``t, x_1, y_1, ..., x_N, y_N``.

An optional header row (any first row that is not numeric, e.g. ``t,x1,y1,x2,y2``) and
lines starting with ``#`` are skipped; blank lines are ignored. Times must be finite and
strictly increasing; positions finite and within
:data:`taut._validate.MAX_SHEET_LENGTH`. Errors name the file row (1-based, as an editor
shows it).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validate import MAX_BATCH, MAX_SHEET_LENGTH
from ..errors import InvalidTrajectoryError
from .files import read_text, write_text_atomic
from .._repr import CompactRepr

__all__ = ["Trajectory", "load_trajectory", "parse_trajectory", "save_trajectory"]


@dataclass(frozen=True, eq=False, repr=False)
class Trajectory(CompactRepr):
    """A time series of formations.

    Attributes
    ----------
    time : ndarray, shape (T,)
        Strictly increasing time stamps (any unit, e.g. s).
    formations : ndarray, shape (T, N, 2)
        Robot positions per step.
    """

    time: np.ndarray
    formations: np.ndarray

    @property
    def n_robots(self) -> int:
        return int(self.formations.shape[1])

    def __len__(self) -> int:
        return int(self.time.shape[0])


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def parse_trajectory(lines: list[str], *, n_robots: int | None = None,
                     source: str = "trajectory") -> Trajectory:
    """Parse CSV text lines (see module docstring).

    Parameters
    ----------
    lines : list of str
    n_robots : int, optional
        Expected robot count (rows must then have ``1 + 2 n_robots`` columns).
    source : str
        Name used in error fields (the file name).

    Raises
    ------
    InvalidTrajectoryError
        No data rows, a row of the wrong width, a non-numeric cell, NaN/inf, or time
        stamps that do not strictly increase.
    """
    rows: list[list[float]] = []
    where: list[int] = []
    header_done = False
    for lineno, row in enumerate(csv.reader(lines), 1):
        cells = [c.strip() for c in row]
        if not cells or all(c == "" for c in cells) or cells[0].startswith("#"):
            continue
        if not header_done:
            header_done = True
            if not all(_is_number(c) for c in cells):
                continue                                     # header row
        bad = [c for c in cells if not _is_number(c)]
        if bad:
            raise InvalidTrajectoryError(f"{source}:{lineno}", f"not a number: {bad[0]!r}")
        rows.append([float(c) for c in cells])
        where.append(lineno)
    if not rows:
        raise InvalidTrajectoryError(source, "no data rows (expected t, x1, y1, ..., xN, yN)")
    width = len(rows[0]) if n_robots is None else 1 + 2 * n_robots
    if n_robots is None and (width < 7 or width % 2 == 0):
        raise InvalidTrajectoryError(
            f"{source}:{where[0]}", f"has {width} columns; expected 1 + 2N (time, then x, y "
            "for each of N >= 3 robots)")
    for r, lineno in zip(rows, where):
        if len(r) != width:
            raise InvalidTrajectoryError(
                f"{source}:{lineno}", f"has {len(r)} columns, expected {width} (time, then "
                f"x, y for each of {(width - 1) // 2} robots)")
    data = np.array(rows, dtype=np.float64)
    finite = np.isfinite(data)
    if not finite.all():
        k = int(np.argmax(~finite.all(axis=1)))
        raise InvalidTrajectoryError(f"{source}:{where[k]}", "contains NaN or infinite values")
    big = np.abs(data[:, 1:]) > MAX_SHEET_LENGTH
    if big.any():
        k = int(np.argmax(big.any(axis=1)))
        raise InvalidTrajectoryError(f"{source}:{where[k]}", f"a position exceeds the accepted "
                                     f"range |x|, |y| <= {MAX_SHEET_LENGTH:g} sheet units")
    if len(data) * (width - 1) // 2 > MAX_BATCH:
        raise InvalidTrajectoryError(source, f"more than {MAX_BATCH} robot positions")
    t = data[:, 0]
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0)) + 1
        raise InvalidTrajectoryError(
            f"{source}:{where[k]}", f"time {t[k]:g} does not increase (previous row has "
            f"{t[k - 1]:g}); time stamps must be strictly increasing")
    return Trajectory(t, data[:, 1:].reshape(len(t), -1, 2))


def load_trajectory(path: str | Path, *, n_robots: int | None = None) -> Trajectory:
    """Read a trajectory CSV file (see module docstring and :func:`parse_trajectory`).

    Raises
    ------
    ScenarioError
        Missing or unreadable file.
    InvalidTrajectoryError
        Malformed content.
    """
    text = read_text(path)
    return parse_trajectory(text.splitlines(), n_robots=n_robots, source=Path(path).name)


def save_trajectory(path: str | Path, time: np.ndarray, formations: np.ndarray) -> None:
    """Write ``time`` (T,) and ``formations`` (T, N, 2) as a trajectory CSV with header."""
    t = np.asarray(time, dtype=float)
    R = np.asarray(formations, dtype=float)
    n = R.shape[1]
    header = ["t"] + [f"{c}{i + 1}" for i in range(n) for c in ("x", "y")]
    fh = io.StringIO(newline="")
    w = csv.writer(fh)
    w.writerow(header)
    for k in range(len(t)):
        w.writerow([repr(float(t[k]))] + [repr(float(v)) for v in R[k].ravel()])
    write_text_atomic(path, fh.getvalue())          # whole or not at all
