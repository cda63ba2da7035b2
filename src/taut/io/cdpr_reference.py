"""Platform references from CSV files: columns ``time, x, y, z, roll, pitch, yaw`` (s, m, rad),
one header line, comma separated (``#`` comment lines allowed), read with the standard
:mod:`csv` module; an error names the line of the file (comment lines counted).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..cdpr.model.robot import CableRobot
from ..cdpr.control.references import Reference, reference_from_samples
from ..errors import ScenarioError
from .files import read_text

__all__ = ["read_reference_csv", "write_reference_csv", "COLUMNS"]

COLUMNS = ("time", "x", "y", "z", "roll", "pitch", "yaw")


def read_reference_csv(robot: CableRobot, path: str | Path) -> Reference:
    """Read a reference CSV and build the :class:`Reference` (velocities by finite
    differences).

    Raises
    ------
    ScenarioError
        Missing or unreadable file, wrong header, a non-numeric cell (its line in the file
        named: field ``reference[LINE]``).
    InvalidTrajectoryError, InfeasiblePoseError
        Non-increasing times, NaN, implausible speeds, poses outside the frame.
    """
    text = read_text(path)
    reader = csv.reader(io.StringIO(text, newline=""))
    header: tuple[str, ...] | None = None
    rows = []
    try:
        for cells in reader:
            line = reader.line_num                 # line of the file, comments counted
            if not "".join(cells).strip() or cells[0].lstrip().startswith("#"):
                continue
            if header is None:
                header = tuple(h.strip().lower() for h in cells)
                if header != COLUMNS:
                    raise ScenarioError("reference", f"{path}: header must be "
                                                     f"{','.join(COLUMNS)}")
                continue
            rows.append(_row(cells, line))
    except csv.Error as exc:
        raise ScenarioError(f"reference[{reader.line_num}]", f"line {reader.line_num}: "
                                                            f"{exc}") from None
    if header is None:
        raise ScenarioError("reference", f"{path}: empty file")
    if len(rows) < 3:
        raise ScenarioError("reference", f"{path}: needs at least 3 samples")
    data = np.array(rows)
    return reference_from_samples(robot, data[:, 0], data[:, 1:])


def _row(cells: list[str], line: int) -> list[float]:
    """The numbers of one data row; errors name its line in the file."""
    if len(cells) != len(COLUMNS):
        raise ScenarioError(f"reference[{line}]", f"line {line}: expected {len(COLUMNS)} "
                                                  f"columns, got {len(cells)}")
    try:
        return [float(c) for c in cells]
    except ValueError:
        raise ScenarioError(f"reference[{line}]", f"line {line}: non-numeric value") from None


def write_reference_csv(reference: Reference, path: str | Path) -> None:
    """Write the poses of a :class:`Reference` as a reference CSV."""
    data = np.column_stack([reference.times, reference.poses])
    np.savetxt(str(path), data, delimiter=",", header=",".join(COLUMNS), comments="",
               fmt="%.9g")
