"""Platform references from CSV files: columns ``time, x, y, z, roll, pitch, yaw`` (s, m, rad),
one header line, comma separated (``#`` comment lines allowed).
"""

from __future__ import annotations

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
        Missing or unreadable file, wrong header, a non-numeric cell (row named).
    InvalidTrajectoryError, InfeasiblePoseError
        Non-increasing times, NaN, implausible speeds, poses outside the frame.
    """
    text = read_text(path)
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise ScenarioError("reference", f"{path}: empty file")
    header = tuple(h.strip().lower() for h in lines[0].split(","))
    if header != COLUMNS:
        raise ScenarioError("reference", f"{path}: header must be {','.join(COLUMNS)}")
    rows = []
    for i, ln in enumerate(lines[1:], start=2):
        cells = ln.split(",")
        if len(cells) != len(COLUMNS):
            raise ScenarioError(f"reference[{i}]", f"expected {len(COLUMNS)} columns, got "
                                                    f"{len(cells)}")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            raise ScenarioError(f"reference[{i}]", "non-numeric value") from None
    if len(rows) < 3:
        raise ScenarioError("reference", f"{path}: needs at least 3 samples")
    data = np.array(rows)
    return reference_from_samples(robot, data[:, 0], data[:, 1:])


def write_reference_csv(reference: Reference, path: str | Path) -> None:
    """Write the poses of a :class:`Reference` as a reference CSV."""
    data = np.column_stack([reference.times, reference.poses])
    np.savetxt(str(path), data, delimiter=",", header=",".join(COLUMNS), comments="",
               fmt="%.9g")
