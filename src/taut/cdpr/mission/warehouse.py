"""The warehouse a mobile cable robot works in (issue 30): floor, shelves, start, tasks.

Frames and units (SI: m, kg, rad). The *world* frame is the warehouse floor's, z up, the
ground at ``z = 0``. The *robot* frame is the frame the cable-robot model is written in
(the preset's frame: FASTKIT's bases at ``x = -3`` and ``x = +3`` facing each other, the
cable plane ``y = 0`` between them). A *pose* ``(x, y, yaw)`` of the coupled bases places
the robot frame in the world: its origin at ``(x, y, 0)``, turned by ``yaw`` about z.
In navigation mode the bases are coupled (platform locked, cables still), so one pose
places both; :func:`coupled_footprint` is the rigid footprint they sweep.

How a pick on a shelf face maps into the cable robot's frame (docs/mission.md): the bases
park parallel to the shelf face, so the cable plane ``y = 0`` runs along the face at
``standoff`` metres from it. A point ``p`` (world) becomes ``q = R(-yaw) (p - (x, y, 0))``
in the robot frame; the platform goes to ``(q_x, 0, q_z)`` (its reference point in the
cable plane) and the gripper reaches ``|q_y| <= gripper_reach`` horizontally across the
plane to take or set the box (:func:`to_robot_frame`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Polygon

from ..._geometry import convex_hull_2d
from ..._validate import (MAX_CDPR_LENGTH_M, MAX_SPEED, as_array, as_bounded, as_flag,
                          as_mass, check_range, require_instance, require_instances)
from ...errors import InvalidInputError, InvalidModelError
from ..model.robot import CableRobot

#: Default shelf height (:class:`Shelf`), m.
SHELF_HEIGHT = 2.5

__all__ = ["Shelf", "Task", "Warehouse", "coupled_footprint", "to_robot_frame",
           "to_world_frame"]


def _polygon(value: Any, fld: str) -> Polygon:
    """A simple polygon of positive area, m (a shapely Polygon or its (k, 2) vertices)."""
    if isinstance(value, Polygon):
        if value.interiors:
            raise InvalidInputError(fld, "must be a polygon without holes")
        value = np.asarray(value.exterior.coords)[:-1]
    pts = check_range(as_array(value, fld, shape=(None, 2)), fld, MAX_CDPR_LENGTH_M, "m")
    if len(pts) < 3:
        raise InvalidInputError(fld, f"a polygon needs at least 3 vertices, got {len(pts)}")
    poly = Polygon(pts)
    if not poly.is_valid or not poly.area > 0:
        raise InvalidInputError(fld, "must be a simple polygon with positive area "
                                     "(no self-intersections)")
    return shapely.geometry.polygon.orient(poly, 1.0)


@dataclass(frozen=True, eq=False)
class Shelf:
    """A rack (or a kitting station's table): a footprint the bases must not touch.

    Parameters
    ----------
    name : str
    footprint : shapely.Polygon or array_like (k, 2)
        Ground footprint, m (simple polygon). The coupled bases' whole footprint (cables
        and locked platform between the bases included) keeps off it while navigating.
    height : float, default :data:`SHELF_HEIGHT`
        Height of the shelf's top above the floor, m: the solid ``footprint x [0, height]``
        the cables must not touch at a site (ASSUMPTION when the file gives none: a 2.5 m
        rack).
    """

    name: str
    footprint: Any
    height: float = SHELF_HEIGHT

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInputError("shelves.name", "must be a non-empty string")
        object.__setattr__(self, "footprint",
                           _polygon(self.footprint, f"shelves[{self.name}].footprint"))
        object.__setattr__(self, "height", as_bounded(self.height,
                                                      f"shelves[{self.name}].height",
                                                      MAX_CDPR_LENGTH_M, "m"))


@dataclass(frozen=True, eq=False)
class Task:
    """A box to move from ``pick`` to ``place`` (world points, m) with ``mass`` kg."""

    name: str
    pick: Any
    place: Any
    mass: float

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInputError("tasks.name", "must be a non-empty string")
        f = f"tasks[{self.name}]"
        for key in ("pick", "place"):
            p = check_range(as_array(getattr(self, key), f"{f}.{key}", shape=(3,)),
                            f"{f}.{key}", MAX_CDPR_LENGTH_M, "m")
            if p[2] < 0:
                raise InvalidInputError(f"{f}.{key}", f"height {p[2]:g} m is below the floor")
            p.setflags(write=False)
            object.__setattr__(self, key, p)
        object.__setattr__(self, "mass", as_mass(self.mass, f"{f}.mass"))


@dataclass(frozen=True, eq=False)
class Warehouse:
    """A validated warehouse: the robot, its floor, the shelves, where it starts, its tasks.

    Parameters
    ----------
    robot : CableRobot
        The cable robot (at least one mobile base), in its own frame (module docstring).
    floor : shapely.Polygon or array_like (k, 2)
        The free floor, m; its boundary is the walls.
    shelves : sequence of Shelf
        Racks and stations inside the floor, not overlapping, unique names.
    start : array_like (3,)
        ``(x, y, yaw)`` of the coupled bases at the start, m and rad.
    tasks : sequence of Task
        Unique names.
    gripper_reach : float, default 1.0
        How far across the cable plane the gripper takes or sets a box, m. ASSUMPTION (the
        FASTKIT paper gives no number): a telescopic gripper of 1 m.
    standoff : float, default 0.95
        Distance from a shelf face to the cable plane when the bases park in front of it,
        m: half the width of a base with its stabilisers out (0.75 m for FASTKIT) plus
        ``clearance`` and a little play.
    clearance : float, default 0.1
        Least gap between the bases (their whole coupled footprint) and any wall or shelf,
        m, while driving and when parked.
    max_speed : float, default 0.5
        Speed limit of the coupled bases while navigating, m/s. ASSUMPTION (not in the
        paper; its task-mode base limit is 0.2 m/s, eqs. 10-12).
    max_accel : float, default 0.25
        Acceleration limit of the coupled bases, m/s^2 (ASSUMPTION).
    max_turn_rate : float, default 0.2
        Turning-rate limit of the coupled bases, rad/s (the paper's 0.2 rad/s, eq. 10).
    friction : float or None, default 0.5
        Ground friction coefficient of the bases' wheels and stabiliser feet (sliding
        condition); None: sliding not modelled. ASSUMPTION (rubber on concrete).
    name : str

    Attributes
    ----------
    body : ndarray (p, 2)
        :func:`coupled_footprint` of the robot, robot frame, m.
    """

    robot: CableRobot
    floor: Any
    shelves: tuple[Shelf, ...]
    start: Any
    tasks: tuple[Task, ...]
    gripper_reach: float = 1.0
    standoff: float = 0.95
    clearance: float = 0.1
    max_speed: float = 0.5
    max_accel: float = 0.25
    max_turn_rate: float = 0.2
    friction: float | None = 0.5
    name: str = "warehouse"
    body: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        s = object.__setattr__
        require_instance(self.robot, CableRobot, "robot")
        if not any(b.mobile for b in self.robot.bases):
            raise InvalidModelError("robot", "a warehouse robot needs mobile bases")
        floor = _polygon(self.floor, "floor")
        s(self, "floor", floor)
        shelves = require_instances(self.shelves, Shelf, "shelves")
        names = [sh.name for sh in shelves]
        for k, sh in enumerate(shelves):
            if names.index(sh.name) != k:
                raise InvalidInputError(f"shelves[{k}].name", f"name {sh.name!r} is used twice")
            if not floor.contains(sh.footprint):
                raise InvalidInputError(f"shelves[{k}].footprint",
                                        f"shelf {sh.name!r} is not inside the floor")
            for j in range(k):
                if shelves[j].footprint.intersects(sh.footprint):
                    raise InvalidInputError(f"shelves[{k}].footprint",
                                            f"shelf {sh.name!r} overlaps shelf "
                                            f"{shelves[j].name!r}")
        s(self, "shelves", shelves)
        start = check_range(as_array(self.start, "start", shape=(3,)), "start",
                            MAX_CDPR_LENGTH_M, "m or rad")
        start.setflags(write=False)
        s(self, "start", start)
        tasks = require_instances(self.tasks, Task, "tasks", min_count=1)
        tnames = [t.name for t in tasks]
        for k, t in enumerate(tasks):
            if tnames.index(t.name) != k:
                raise InvalidInputError(f"tasks[{k}].name", f"name {t.name!r} is used twice")
        s(self, "tasks", tasks)
        for key, limit, unit in (("gripper_reach", MAX_CDPR_LENGTH_M, "m"),
                                 ("standoff", MAX_CDPR_LENGTH_M, "m"),
                                 ("max_speed", MAX_SPEED, "m/s"),
                                 ("max_accel", MAX_SPEED, "m/s^2"),
                                 ("max_turn_rate", MAX_SPEED, "rad/s")):
            s(self, key, as_bounded(getattr(self, key), key, limit, unit))
        s(self, "clearance", as_bounded(self.clearance, "clearance", MAX_CDPR_LENGTH_M, "m",
                                        positive=False))
        if self.friction is not None:
            s(self, "friction", as_bounded(self.friction, "friction", MAX_SPEED, "",
                                           positive=False))
        if not isinstance(self.name, str):
            raise InvalidInputError("name", "must be a string")
        body = coupled_footprint(self.robot)
        body.setflags(write=False)
        s(self, "body", body)


def coupled_footprint(robot: CableRobot, *, deployed: bool = False) -> np.ndarray:
    """The rigid footprint of the coupled bases, robot frame, m: (p, 2), counter-clockwise.

    The convex hull of every mobile base's support polygon (wheels; with ``deployed``, the
    stabiliser feet too) at the model's placement. It contains the union of the bases'
    footprints and the ground under the cables and the locked platform between them (at
    FASTKIT's heights, up to 2.4 m: nothing taller than the floor may pass under them), so
    keeping it clear keeps the whole robot clear.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> coupled_footprint(load_cdpr_model("fastkit")).round(2).tolist()
    [[-3.45, -0.6], [3.45, -0.6], [3.45, 0.6], [-3.45, 0.6]]
    """
    require_instance(robot, CableRobot, "robot")
    deployed = as_flag(deployed, "deployed")
    pts = []
    for b in robot.bases:
        if not b.mobile:
            continue
        poly = b.footprint
        if deployed and b.stabilisers is not None:
            poly = np.vstack([poly, b.stabilisers])
        pts.append(b.to_world(np.column_stack([poly, np.zeros(len(poly))]))[:, :2])
    if not pts:
        raise InvalidModelError("robot", "no mobile base: nothing to navigate")
    return convex_hull_2d(np.vstack(pts))


def _rot(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s], [s, c]])


def _frame_args(pose: Any, points: Any) -> tuple[np.ndarray, np.ndarray]:
    """A validated pose (3,) and a copy of points (..., 3) or (..., 2), m."""
    q = check_range(as_array(pose, "pose", shape=(3,)), "pose", MAX_CDPR_LENGTH_M, "m or rad")
    p = check_range(as_array(points, "points"), "points", MAX_CDPR_LENGTH_M, "m")
    if p.ndim == 0 or p.shape[-1] not in (2, 3) or p.size == 0:
        raise InvalidInputError("points", "must be points (..., 3) or (..., 2), m")
    return q, np.array(p, dtype=float, copy=True)


def to_robot_frame(pose: Any, points: Any) -> np.ndarray:
    """World points ``(..., 3)`` (or ``(..., 2)``) in the robot frame of the coupled bases
    at ``pose`` = (x, y, yaw), m: ``R(-yaw) (p - (x, y))``, heights unchanged."""
    q, p = _frame_args(pose, points)
    p[..., :2] = (p[..., :2] - q[:2]) @ _rot(float(q[2]))
    return p


def to_world_frame(pose: Any, points: Any) -> np.ndarray:
    """Robot-frame points ``(..., 3)`` (or ``(..., 2)``) in the world, the inverse of
    :func:`to_robot_frame`."""
    q, p = _frame_args(pose, points)
    p[..., :2] = p[..., :2] @ _rot(float(q[2])).T + q[:2]
    return p
