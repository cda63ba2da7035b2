"""Kinematic redundancy of the active base between tasks (private; issue 30, part 4).

Well-defined version (documented choice; the paper leaves FASTKIT's redundancy planning
open): at a site, before a task's ``pick``, the active base may move by an offset ``d``
along its own x axis (parallel to the shelf face, in the cable plane) from the site's
placement. The move is: the active base's stabilisers retract (``STABILISER_S``), it
drives ``|d - d_prev|`` on its wheels at the task-mode base limits (FASTKIT eq. 10:
0.2 m/s) and the warehouse's acceleration limit, rest to rest, while the cables hold the
platform at rest, then its stabilisers deploy again (``STABILISER_S``). Before the site's
retract it returns to ``d = 0`` (the coupled footprint navigates at the model placement).

Decision, per task, greedy in the site's task order: among the candidate offsets (the
footprint still clear of walls and shelves, every motion of the task time-optimal and
feasible with the moved base) the one with the least ``motion time + move time`` is taken
(``d_prev`` kept at zero cost). The drive is monitored like a deploy: the platform held
with the active base on its wheels at both ends of the drive, then with every stabiliser
down.

Measured on ``examples/cdpr/warehouse.yaml`` (docs in examples/cdpr/README.md): a 0.6 m
offset saves at most 0.24 s of a task's motions while a move costs at least
``2 STABILISER_S`` = 6 s, so the planner keeps the active base still.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..deployment.placement import place_bases
from ..model.robot import CableRobot
from ..kinematics.modes import fastkit_motion_limits

__all__ = ["Reposition", "shifted", "drive_time"]


@dataclass(frozen=True)
class Reposition:
    """One task's choice of active-base offset.

    Attributes
    ----------
    task : str
    offset : float
        Chosen offset of the active base along its x axis from the site's placement, m.
    saved : float
        Motion time of the task at the chosen offset less at the previous one, s
        (negative: saved).
    move_time : float
        Time the move costs (0 when the base stays), s.
    best_saving : float
        Largest motion-time saving of any feasible candidate offset, s (>= 0).
    """

    task: str
    offset: float
    saved: float
    move_time: float
    best_saving: float


def active_index(robot: CableRobot) -> int:
    """Index of the base that moves in task mode (named ``active``, else the first
    mobile base)."""
    names = [b.name for b in robot.bases]
    if "active" in names:
        return names.index("active")
    return next(k for k, b in enumerate(robot.bases) if b.mobile)


def shifted(robot: CableRobot, offset: float) -> CableRobot:
    """``robot`` with its active base moved ``offset`` m along its own x axis."""
    if offset == 0.0:
        return robot
    b = robot.bases[active_index(robot)]
    th = float(b.pose[2])
    return place_bases(robot, {b.name: b.pose + offset * np.array([np.cos(th), np.sin(th),
                                                                    0.0])})


def drive_time(distance: float, accel: float, stabiliser_s: float) -> float:
    """Time of one move of the active base over ``distance`` m (module docstring), s."""
    if distance <= 0.0:
        return 0.0
    v = float(fastkit_motion_limits().base_max[0])
    drive = (distance / v + v / accel if distance >= v * v / accel
             else 2.0 * np.sqrt(distance / accel))
    return 2.0 * stabiliser_s + drive
