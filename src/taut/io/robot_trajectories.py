"""Executed robot trajectories (:func:`taut.plan.robot_trajectories`) as CSV or JSON files.

CSV: a header row and one row per sample, every column named with its unit:
``t_s, x_1_m, y_1_m, heading_1_rad, ..., x_N_m, y_N_m, heading_N_rad, object_x_m,
object_y_m, object_z_m`` (robots 1-based). JSON: ``times_s`` (T,), ``poses_m_rad`` (T, N, 3:
x m, y m, heading rad), ``object_m`` (T, 3) and the outcome (``success``, ``status``,
``message``, ``drive``, durations, limits and measured peaks, each key with its unit).
Numbers are written with 17 significant digits, so both read back exactly
(:func:`load_robot_trajectories`).
"""

from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidTrajectoryError
from .files import read_text, write_text_atomic

if TYPE_CHECKING:
    from ..plan.execution.trajectories import RobotTrajectories

__all__ = ["ExecutedTrajectories", "robot_trajectories_to_dict", "save_robot_trajectories",
           "load_robot_trajectories"]


@dataclass(frozen=True, eq=False)
class ExecutedTrajectories:
    """Trajectories read from a file: ``times`` (T,) s, ``poses`` (T, N, 3) m, m, rad,
    ``object`` (T, 3) m."""

    times: np.ndarray
    poses: np.ndarray
    object: np.ndarray


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


def load_robot_trajectories(path: str | Path) -> ExecutedTrajectories:
    """Read a file written by :func:`save_robot_trajectories`.

    Raises
    ------
    ScenarioError
        Missing or unreadable file.
    InvalidTrajectoryError
        Malformed content (the message names the row or key).
    """
    text = read_text(path)
    if Path(path).suffix.lower() != ".csv":
        try:
            doc = json.loads(text)
            times = np.asarray(doc["times_s"], float).reshape(-1)
            poses = np.asarray(doc["poses_m_rad"], float).reshape(len(times), -1, 3)
            obj = np.asarray(doc["object_m"], float).reshape(len(times), 3)
        except (ValueError, KeyError, TypeError) as exc:
            raise InvalidTrajectoryError(Path(path).name, f"not a trajectories file: {exc}"
                                         ) from None
        return ExecutedTrajectories(times, poses, obj)
    rows = list(csv.reader(io.StringIO(text)))
    if not rows or (len(rows[0]) - 4) % 3 or rows[0] != _header((len(rows[0]) - 4) // 3):
        raise InvalidTrajectoryError(Path(path).name, "row 1: expected the header t_s, "
                                     "x_1_m, y_1_m, heading_1_rad, ..., object_z_m")
    try:
        data = np.array([[float(v) for v in r] for r in rows[1:] if r], float)
    except ValueError as exc:
        raise InvalidTrajectoryError(Path(path).name, f"a row is not numeric: {exc}") from None
    data = data.reshape(-1, len(rows[0]))
    n = (data.shape[1] - 4) // 3
    return ExecutedTrajectories(data[:, 0], data[:, 1:1 + 3 * n].reshape(-1, n, 3),
                                data[:, 1 + 3 * n:])
