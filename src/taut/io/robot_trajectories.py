"""Executed robot trajectories (:func:`taut.plan.robot_trajectories`) as CSV or JSON files.

CSV: a header row and one row per sample, every column named with its unit:
``t_s, x_1_m, y_1_m, heading_1_rad, ..., x_N_m, y_N_m, heading_N_rad, object_x_m,
object_y_m, object_z_m`` (robots 1-based). JSON: ``times_s`` (T,), ``poses_m_rad`` (T, N, 3:
x m, y m, heading rad), ``object_m`` (T, 3) and the outcome (``success``, ``status``,
``message``, ``drive``, durations, limits and measured peaks, each key with its unit).
Numbers are written with 17 significant digits, so both read back exactly
(:func:`load_robot_trajectories`).

The JSON form is read with a strict schema (:func:`robot_trajectories_from_mapping`):
unknown keys, a boolean or a string where a number is expected, and ``null`` or a
non-finite number in ``times_s``, ``poses_m_rad`` or ``object_m`` are refused naming the
key. ``null`` is accepted only where the writer puts it for a non-finite value: a failed
outcome's durations and peaks, and limits that were not set (infinite).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Optional

import numpy as np

from .._outcome import Status
from ..errors import InvalidTrajectoryError, ScenarioError
from .files import Integer, Number, StrictModel, parse_mapping, read_text, validate_mapping, \
    write_text_atomic

if TYPE_CHECKING:
    from ..plan.execution.trajectories import RobotTrajectories

__all__ = ["ExecutedTrajectories", "robot_trajectories_to_dict", "save_robot_trajectories",
           "load_robot_trajectories", "robot_trajectories_from_mapping"]


@dataclass(frozen=True, eq=False)
class ExecutedTrajectories:
    """Trajectories read from a file: ``times`` (T,) s, ``poses`` (T, N, 3) m, m, rad,
    ``object`` (T, 3) m."""

    times: np.ndarray
    poses: np.ndarray
    object: np.ndarray


# --- the JSON form's schema (written by robot_trajectories_to_dict) ----------------------

Pose = tuple[Number, Number, Number]
#: A summary number the writer may have written as ``null`` (non-finite: NaN or inf).
MaybeNumber = Optional[Number]


class _Limits(StrictModel):
    max_speed_mps: MaybeNumber
    max_accel_mps2: MaybeNumber
    max_yaw_rate_radps: MaybeNumber
    reform_speed_mps: MaybeNumber


class _Peaks(StrictModel):
    speed_mps: MaybeNumber
    accel_mps2: MaybeNumber
    yaw_rate_radps: MaybeNumber


class _TrajectoriesFile(StrictModel):
    success: bool
    status: Status
    message: str
    # the choices of taut.plan.execution._drives.DRIVES (tests/io/test_robot_trajectories_file.py
    # checks they agree; importing the planner here would slow every loader down)
    drive: Literal["holonomic", "differential"]
    duration_s: MaybeNumber
    plan_duration_s: MaybeNumber
    turns_in_place: Integer
    limits: _Limits
    peaks: _Peaks
    times_s: list[Number]
    poses_m_rad: list[list[Pose]]
    object_m: list[Pose]


def robot_trajectories_from_mapping(data: dict[str, Any]) -> ExecutedTrajectories:
    """Executed trajectories from the parsed JSON form (module docstring).

    Raises
    ------
    InvalidTrajectoryError
        An unknown or missing key, a value of the wrong type (a boolean or a string for a
        number, ``null`` in a sample), or samples whose counts disagree; the field is the
        key's dotted path (``poses_m_rad[3][1][2]``).
    """
    try:
        raw = validate_mapping(_TrajectoriesFile, data)
    except ScenarioError as exc:
        raise InvalidTrajectoryError(exc.field, exc.problem) from None
    T = len(raw.times_s)
    for key, rows in (("poses_m_rad", raw.poses_m_rad), ("object_m", raw.object_m)):
        if len(rows) != T:
            raise InvalidTrajectoryError(key, f"{len(rows)} samples; times_s has {T}")
    n = len(raw.poses_m_rad[0]) if T else 0
    for k, sample in enumerate(raw.poses_m_rad):
        if len(sample) != n or n == 0:
            raise InvalidTrajectoryError(f"poses_m_rad[{k}]", f"{len(sample)} robots; "
                                         f"sample 0 has {n} (at least 1)")
    return ExecutedTrajectories(np.array(raw.times_s, float).reshape(T),
                                np.array(raw.poses_m_rad, float).reshape(T, n, 3),
                                np.array(raw.object_m, float).reshape(T, 3))


def robot_trajectories_to_dict(tr: RobotTrajectories) -> dict[str, Any]:
    """The JSON form of executed trajectories (module docstring)."""
    vmax, amax, wmax, vref = tr.limits
    return {
        "success": bool(tr.success), "status": tr.status, "message": tr.message,
        "drive": tr.drive, "duration_s": tr.duration, "plan_duration_s": tr.plan_duration,
        "turns_in_place": tr.turns,
        "limits": {"max_speed_mps": vmax, "max_accel_mps2": amax, "max_yaw_rate_radps": wmax,
                   "reform_speed_mps": vref},
        "peaks": {"speed_mps": tr.peak_speed, "accel_mps2": tr.peak_accel,
                  "yaw_rate_radps": tr.peak_yaw_rate},
        "times_s": np.asarray(tr.times, float).tolist(),
        "poses_m_rad": np.asarray(tr.poses, float).tolist(),
        "object_m": np.asarray(tr.object, float).tolist(),
    }


def _header(n: int) -> list[str]:
    cols = ["t_s"]
    for i in range(1, n + 1):
        cols += [f"x_{i}_m", f"y_{i}_m", f"heading_{i}_rad"]
    return cols + ["object_x_m", "object_y_m", "object_z_m"]


def save_robot_trajectories(path: str | Path, tr: RobotTrajectories) -> None:
    """Write ``tr`` as CSV (``.csv``) or JSON (any other suffix), all at once."""
    if Path(path).suffix.lower() != ".csv":
        from .serialize import to_json          # NaN (a failed outcome) as null
        write_text_atomic(path, to_json(robot_trajectories_to_dict(tr), indent=None) + "\n")
        return
    T, n = tr.poses.shape[:2]
    fh = io.StringIO(newline="")
    w = csv.writer(fh)
    w.writerow(_header(n))
    rows = np.column_stack([tr.times, tr.poses.reshape(T, 3 * n), tr.object])
    for row in rows:
        w.writerow([repr(float(v)) for v in row])
    write_text_atomic(path, fh.getvalue())


def _csv_row(name: str, row: int, cells: list[str], width: int) -> list[float]:
    """One CSV sample: ``width`` finite numbers (the writer never writes NaN or inf)."""
    if len(cells) != width:
        raise InvalidTrajectoryError(name, f"row {row}: {len(cells)} cells; the header has "
                                     f"{width}")
    try:
        values = [float(v) for v in cells]
    except ValueError:
        raise InvalidTrajectoryError(name, f"row {row}: a cell is not a number") from None
    if not np.all(np.isfinite(values)):
        raise InvalidTrajectoryError(name, f"row {row}: a cell is NaN or infinite")
    return values


def load_robot_trajectories(path: str | Path) -> ExecutedTrajectories:
    """Read a file written by :func:`save_robot_trajectories`.

    Raises
    ------
    ScenarioError
        Missing, unreadable or too large file, or (JSON) invalid JSON, a key given twice
        or a top level that is not a mapping.
    InvalidTrajectoryError
        Malformed content (CSV: the message names the row; JSON: the field is the key's
        dotted path, :func:`robot_trajectories_from_mapping`).
    """
    text = read_text(path)
    if Path(path).suffix.lower() != ".csv":
        return robot_trajectories_from_mapping(parse_mapping(text, str(path), suffix=".json"))
    rows = list(csv.reader(io.StringIO(text)))
    if not rows or (len(rows[0]) - 4) % 3 or rows[0] != _header((len(rows[0]) - 4) // 3):
        raise InvalidTrajectoryError(Path(path).name, "row 1: expected the header t_s, "
                                     "x_1_m, y_1_m, heading_1_rad, ..., object_z_m")
    data = np.array([_csv_row(Path(path).name, k, r, len(rows[0]))
                     for k, r in enumerate(rows[1:], start=2) if r], float)
    data = data.reshape(-1, len(rows[0]))
    n = (data.shape[1] - 4) // 3
    return ExecutedTrajectories(data[:, 0], data[:, 1:1 + 3 * n].reshape(-1, n, 3),
                                data[:, 1 + 3 * n:])
