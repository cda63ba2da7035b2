"""Robot headings along a plan's path for each drive, and the turns in place they need.

The path is the plan's samples (rigid intervals are rigid motions, formation changes move
every robot straight: :func:`taut.plan.checks.verify.verify_motion`'s reading of a sampled
motion). A *holonomic* robot keeps its heading fixed in the formation (it turns with the
team). A *differential-drive* robot faces its direction of motion: at every sample its
heading is the direction of the interval it leaves; where that direction turns by more
than ``TURN_IN_PLACE`` at a sample the team stops there and the robots turn in place (a
turn in place moves no robot, so the object does not move either); smaller turns are
steered while moving. A robot standing still keeps its heading.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _tol

__all__ = ["DRIVES", "Path", "drive_path"]

#: The robot drives :func:`~taut.plan.execution.trajectories.robot_trajectories` knows.
DRIVES: tuple[str, ...] = ("holonomic", "differential")


@dataclass(frozen=True, eq=False)
class Path:
    """Samples of the executed path before timing.

    Attributes
    ----------
    robots : ndarray, shape (M, N, 2)
        Robot positions, m (a turn in place repeats a sample).
    heading : ndarray, shape (M, N)
        Robot headings, rad, unwrapped along time per robot.
    object : ndarray, shape (M, 3)
        The plan's object at each sample, m.
    reform : ndarray of bool, shape (M - 1,)
        Intervals of formation changes (not rigid motions of the team).
    turns : int
        Turns in place inserted.
    """

    robots: np.ndarray
    heading: np.ndarray
    object: np.ndarray
    reform: np.ndarray
    turns: int


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi), rad."""
    return (a + np.pi) % (2 * np.pi) - np.pi


def _directions(step: np.ndarray, start: np.ndarray) -> np.ndarray:
    """Direction of motion (M-1, N), rad, of the robot steps ``step`` (M-1, N, 2); a robot
    standing still keeps its last direction (before its first move: its first one; one
    that never moves: ``start``)."""
    moving = np.linalg.norm(step, axis=2) > _tol.STANDING_STILL
    ang = np.arctan2(step[..., 1], step[..., 0])
    out = np.empty_like(ang)
    for i in range(step.shape[1]):
        idx = np.flatnonzero(moving[:, i])
        if not len(idx):
            out[:, i] = start[i]
            continue
        last = np.maximum.accumulate(np.where(moving[:, i], np.arange(len(ang)), -1))
        out[:, i] = ang[np.where(last < 0, idx[0], last), i]
    return out


def drive_path(robots: np.ndarray, heading: np.ndarray, obj: np.ndarray, reform: np.ndarray,
               drive: str) -> Path:
    """The executed path of ``drive`` (module docstring) along a plan's samples.

    Parameters
    ----------
    robots : ndarray, shape (T, N, 2)
        The plan's robot positions, m (consecutive samples distinct).
    heading : ndarray, shape (T,)
        The formation's heading, rad.
    obj : ndarray, shape (T, 3)
        The plan's object, m.
    reform : ndarray of bool, shape (T - 1,)
        Intervals that are formation changes.
    drive : {"holonomic", "differential"}
    """
    T, N = robots.shape[:2]
    if drive == "holonomic" or T < 2:
        head = np.repeat(np.unwrap(heading)[:, None], N, axis=1)
        return Path(robots, head, obj, reform, 0)
    d = _directions(np.diff(robots, axis=0), np.full(N, heading[0]))     # (T-1, N)
    turn = np.abs(_wrap(np.diff(d, axis=0))).max(axis=1) > _tol.TURN_IN_PLACE   # (T-2,)
    rows_r, rows_h, rows_o, rows_f = [robots[0]], [d[0]], [obj[0]], []
    for k in range(1, T):
        if k < T - 1 and turn[k - 1]:
            rows_r.append(robots[k])                # arrive facing the last direction
            rows_h.append(d[k - 1])
            rows_o.append(obj[k])
            rows_f.append(reform[k - 1])
            rows_f.append(False)                    # the turn in place: nobody moves
        else:
            rows_f.append(reform[k - 1])
        rows_r.append(robots[k])
        rows_h.append(d[min(k, T - 2)])
        rows_o.append(obj[k])
    head = np.asarray(rows_h)
    head = head[0] + np.concatenate([np.zeros((1, N)),
                                     np.cumsum(_wrap(np.diff(head, axis=0)), axis=0)])
    return Path(np.asarray(rows_r), head, np.asarray(rows_o), np.asarray(rows_f, bool),
                int(turn.sum()))
