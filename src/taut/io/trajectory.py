"""Robot trajectories as CSV files: one row per time step, ``t, x_1, y_1, ..., x_N, y_N``.

An optional header row (any first row that is not numeric, e.g. ``t,x1,y1,x2,y2``) and
lines starting with ``#`` are skipped; blank lines are ignored. Times (s: recordings
stamp them as seconds) must lie in ``0..MAX_DURATION_S`` (:mod:`taut._validate`, one day)
and strictly increase; positions finite and within
:data:`taut._validate.MAX_SHEET_LENGTH`; cells plain ASCII decimal numbers. A file holds at
most :data:`MAX_TRAJECTORY_ROWS` data rows of at most :data:`MAX_TRAJECTORY_COLUMNS`
cells (besides the byte limit of :func:`taut.io.files.read_text`). Errors name the file
row (1-based, as an editor shows it) and, for a bad cell, its column.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._validate import MAX_BATCH, MAX_DURATION_S, MAX_ROBOTS, MAX_SHEET_LENGTH
from ..errors import InvalidTrajectoryError
from .files import read_text, write_text_atomic
from .._repr import CompactRepr

__all__ = ["Trajectory", "load_trajectory", "parse_trajectory", "save_trajectory",
           "MAX_TRAJECTORY_ROWS", "MAX_TRAJECTORY_COLUMNS"]


@dataclass(frozen=True, eq=False, repr=False)
class Trajectory(CompactRepr):
    """A time series of formations.

    Attributes
    ----------
    time : ndarray, shape (T,)
        Strictly increasing time stamps, s (within ``0..MAX_DURATION_S`` when loaded
        from a file).
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


#: Most data rows of a trajectory file: 10^5 steps (1000 s at 100 Hz). A 10^6-row file
#: (~23 MB, within the byte limit) took `taut simulate` ~0.7 GB and ~25 s before this limit.
MAX_TRAJECTORY_ROWS = 100_000
#: Most columns of a row: the time, then x, y of each of at most MAX_ROBOTS robots.
MAX_TRAJECTORY_COLUMNS = 1 + 2 * MAX_ROBOTS


def _is_number(cell: str) -> bool:
    """Whether ``cell`` is a plain ASCII decimal number (or nan/inf, refused later with
    their row and column): Python's ``float`` also reads ``1_0`` as 10 and non-ASCII
    digits, which no CSV writer means as numbers."""
    if not cell.isascii() or "_" in cell:
        return False
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _column(k: int, header: list[str] | None) -> str:
    """``column 3 (y1)``: 1-based, with the header's name when there is one."""
    name = header[k] if header is not None and k < len(header) and header[k] else None
    return f"column {k + 1}" + (f" ({name})" if name else "")


#: Rows converted at once by numpy's CSV reader (a block with a bad cell is then read row
#: by row to name it).
_BLOCK_ROWS = 10_000


def _check_cells(cells: list[str], lineno: int, source: str, header: list[str] | None) -> None:
    """Raise for the first cell of a row that is not a plain number, naming its column."""
    for k, c in enumerate(cells):
        if not _is_number(c):
            raise InvalidTrajectoryError(f"{source}:{lineno}", f"{_column(k, header)}: not a "
                                         f"number: {c[:40]!r}")


def _cells(line: str, lineno: int, source: str) -> list[str]:
    """The stripped cells of one CSV line."""
    if line.count(",") >= MAX_TRAJECTORY_COLUMNS:       # before a huge row is split
        raise InvalidTrajectoryError(f"{source}:{lineno}", f"has {line.count(',') + 1} "
                                     f"columns; at most {MAX_TRAJECTORY_COLUMNS} (time, then "
                                     f"x, y of at most {MAX_ROBOTS} robots)")
    if '"' not in line:
        return [c.strip() for c in line.split(",")]
    try:
        rows = list(csv.reader([line]))
    except csv.Error as exc:
        raise InvalidTrajectoryError(f"{source}:{lineno}", f"not CSV ({exc})") from None
    return [c.strip() for c in rows[0]] if rows else []


@dataclass
class _Rows:
    """Data rows (float64, one array per row), their line numbers and the header."""

    data: list[np.ndarray]
    where: list[int]
    header: list[str] | None
    source: str


def _body(lines: list[str], source: str) -> tuple[list[str] | None, list[tuple[int, str]]]:
    """The header (a first row that is not all numbers) and the numbered data lines:
    blank, all-empty and ``#`` comment lines left out."""
    if sum(1 for x in lines if x.strip() and not x.lstrip().startswith("#")) > \
            MAX_TRAJECTORY_ROWS + 1:                   # + a header: refused before parsing
        raise InvalidTrajectoryError(source, f"more than {MAX_TRAJECTORY_ROWS:,} data rows "
                                     "(time steps)")
    header: list[str] | None = None
    body: list[tuple[int, str]] = []
    for lineno, line in enumerate(lines, 1):
        if line.lstrip().startswith("#") or not line.replace(",", "").strip():
            continue
        if line.count(",") >= MAX_TRAJECTORY_COLUMNS or (not body and header is None):
            cells = _cells(line, lineno, source)
            if not body and header is None and not all(_is_number(c) for c in cells):
                header = cells
                continue
        body.append((lineno, line))
    return header, body


def _read_rows(lines: list[str], source: str) -> _Rows:
    """The data rows of CSV ``lines``, converted a block at a time by numpy's CSV reader
    (which reads plain ASCII decimals only, as :func:`_is_number`); a block it refuses is
    read row by row to name the bad cell."""
    header, body = _body(lines, source)
    data: list[np.ndarray] = []
    for i in range(0, len(body), _BLOCK_ROWS):
        block = body[i:i + _BLOCK_ROWS]
        try:
            data += list(np.loadtxt([x for _, x in block], delimiter=",", comments=None,
                                    quotechar='"', ndmin=2, dtype=np.float64))
        except ValueError:                     # a bad cell or a ragged row in the block
            for lineno, line in block:
                cells = _cells(line, lineno, source)
                _check_cells(cells, lineno, source, header)
                data.append(np.array([float(c) for c in cells], dtype=np.float64))
    return _Rows(data, [lineno for lineno, _ in body], header, source)


def _width(rows: _Rows, n_robots: int | None) -> int:
    """The row width every row must have (checked here)."""
    source, where = rows.source, rows.where
    if not rows.data:
        raise InvalidTrajectoryError(source, "no data rows (expected t, x1, y1, ..., xN, yN)")
    width = len(rows.data[0]) if n_robots is None else 1 + 2 * n_robots
    if n_robots is None and (width < 7 or width % 2 == 0):
        raise InvalidTrajectoryError(
            f"{source}:{where[0]}", f"has {width} columns; expected 1 + 2N (time, then x, y "
            "for each of N >= 3 robots)")
    for r, lineno in zip(rows.data, where):
        if len(r) != width:
            raise InvalidTrajectoryError(
                f"{source}:{lineno}", f"has {len(r)} columns, expected {width} (time, then "
                f"x, y for each of {(width - 1) // 2} robots)")
    return width


def parse_trajectory(lines: list[str], *, n_robots: int | None = None,
                     source: str = "trajectory") -> Trajectory:
    """Parse CSV text lines (see module docstring).

    Parameters
    ----------
    lines : list of str
        The file's lines; a quoted cell cannot span lines.
    n_robots : int, optional
        Expected robot count (rows must then have ``1 + 2 n_robots`` columns).
    source : str
        Name used in error fields (the file name).

    Raises
    ------
    InvalidTrajectoryError
        No data rows, more than :data:`MAX_TRAJECTORY_ROWS` rows or
        :data:`MAX_TRAJECTORY_COLUMNS` columns, a row of the wrong width, a cell that is not
        a number or is NaN/inf (naming its row and column), a position past
        :data:`taut._validate.MAX_SHEET_LENGTH`, a time outside ``0..MAX_DURATION_S`` s,
        or time stamps that do not strictly increase.
    """
    rows = _read_rows(lines, source)
    width = _width(rows, n_robots)
    data, where = np.array(rows.data, dtype=np.float64), rows.where
    bad = ~np.isfinite(data)
    if bad.any():
        k = int(np.argmax(bad.any(axis=1)))
        col = _column(int(np.argmax(bad[k])), rows.header)
        raise InvalidTrajectoryError(f"{source}:{where[k]}", f"{col}: NaN or infinite (or "
                                     "past 1.8e308)")
    big = np.abs(data[:, 1:]) > MAX_SHEET_LENGTH
    if big.any():
        k = int(np.argmax(big.any(axis=1)))
        col = _column(1 + int(np.argmax(big[k])), rows.header)
        raise InvalidTrajectoryError(f"{source}:{where[k]}", f"{col}: a position exceeds the "
                                     f"accepted range |x|, |y| <= {MAX_SHEET_LENGTH:g} sheet "
                                     "units")
    if len(data) * (width - 1) // 2 > MAX_BATCH:
        raise InvalidTrajectoryError(source, f"more than {MAX_BATCH} robot positions")
    t = data[:, 0]
    late = (t < 0) | (t > MAX_DURATION_S)
    if late.any():
        k = int(np.argmax(late))
        raise InvalidTrajectoryError(f"{source}:{where[k]}", f"{_column(0, rows.header)}: "
                                     f"time {t[k]:g} s is outside 0..{MAX_DURATION_S:g} s")
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
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")  # not \x0c, \x85...
    return parse_trajectory(lines, n_robots=n_robots, source=Path(path).name)


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
