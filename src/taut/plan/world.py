"""World and team models of the obstacle-crossing planner (planning paper, Sec. II and V).

The world is a planar free-space polygon (corridors, rooms, turns; walls are its boundary)
holding obstacles that stand on the ground, each a circle (a cylinder) or a polygon (a prism)
with a height. The team is the sheet with its ``N`` robots and the physical and motion
parameters of the paper's experiment. Every model is immutable and validated when built;
lengths in metres, times in seconds, angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry import Point, Polygon

from .._validate import MAX_SHEET_LENGTH, MAX_SPEED, as_array, as_bounded, as_points
from .._validate import check_range
from .._validate import require_instances
from ..errors import InvalidInputError, PlanningError
from ..sheet.model import Sheet
from ..sheet.team import SheetTeam
from ._tol import INSCRIBED_CIRCLE_RTOL
from .._repr import CompactRepr

__all__ = ["Obstacle", "World", "Team", "Scenario", "UnknownObstacleError"]


class UnknownObstacleError(InvalidInputError, KeyError):
    """:meth:`World.obstacle` was asked for an id no obstacle has (a ``KeyError`` too, for
    code written against the old behaviour)."""

    def __str__(self) -> str:                  # KeyError would quote the message
        return f"{self.field}: {self.problem}"

#: Segments per quarter circle used to turn a circular obstacle into a shapely polygon
#: (the polygon is circumscribed, so it contains the true circle).
CIRCLE_SEGMENTS = 16


def _circle_polygon(centre: np.ndarray, radius: float) -> Polygon:
    """Polygon containing the disc: vertices on the circle of radius ``r / cos(pi / n)``."""
    n = 4 * CIRCLE_SEGMENTS
    r_out = radius / np.cos(np.pi / n)
    t = (np.arange(n) + 0.5) * 2 * np.pi / n
    return Polygon(np.column_stack([centre[0] + r_out * np.cos(t), centre[1] + r_out * np.sin(t)]))


@dataclass(frozen=True, eq=False, repr=False)
class Obstacle(CompactRepr):
    """An obstacle standing on the ground.

    Parameters
    ----------
    id : str
        Name used in plans (``crossed``/``bypassed`` lists).
    height : float
        Height above the ground, m (> 0).
    center, radius : array_like (2,), float
        A cylinder (give both, and no ``polygon``).
    polygon : array_like, shape (K, 2)
        A prism with this simple footprint, K >= 3 (give it instead of a circle).

    Attributes
    ----------
    geometry : shapely.Polygon
        Footprint (circles as a circumscribed 64-gon).
    mec_center : ndarray, shape (2,)
        Centre of the footprint's minimum enclosing circle (the circle's centre).
    mec_radius : float
        Its radius, m (for a circle, the circumscribed polygon's, 0.03 % larger than
        ``radius``); the obstacle "diameter" of the paper's eq. (4) is twice this.
    """

    id: str
    height: float
    center: np.ndarray | None = None
    radius: float | None = None
    polygon: np.ndarray | None = None
    geometry: Polygon = field(init=False, repr=False)
    mec_center: np.ndarray = field(init=False, repr=False)
    mec_radius: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        f = f"obstacle {self.id!r}"
        object.__setattr__(self, "id", str(self.id))
        object.__setattr__(self, "height", as_bounded(self.height, f"{f}.height",
                                                      MAX_SHEET_LENGTH, "m"))
        if (self.polygon is None) == (self.center is None):
            raise InvalidInputError(f, "give either center and radius (a cylinder) or a "
                                       "polygon, not both or neither")
        if self.polygon is None:
            c = check_range(as_array(self.center, f"{f}.center", shape=(2,)), f"{f}.center",
                            MAX_SHEET_LENGTH, "m")
            if self.radius is None:
                raise InvalidInputError(f"{f}.radius", "required for a circular obstacle")
            r = as_bounded(self.radius, f"{f}.radius", MAX_SHEET_LENGTH, "m")
            geom = _circle_polygon(c, r)
            object.__setattr__(self, "center", c)
            object.__setattr__(self, "radius", r)
            mc, mr = c, r / np.cos(np.pi / (4 * CIRCLE_SEGMENTS))
        else:
            if self.radius is not None:
                raise InvalidInputError(f"{f}.radius", "not allowed with a polygon")
            pts = check_range(as_points(self.polygon, f"{f}.polygon", min_count=3),
                              f"{f}.polygon", MAX_SHEET_LENGTH, "m")
            geom = Polygon(pts)
            if not geom.is_valid or not geom.area > 0:
                raise InvalidInputError(f"{f}.polygon", "must be a simple polygon with "
                                                        "positive area")
            mec = shapely.minimum_bounding_circle(geom)
            mc = np.array(mec.centroid.coords[0])
            mr = float(shapely.minimum_bounding_radius(geom))
            object.__setattr__(self, "polygon", pts)
        object.__setattr__(self, "geometry", geom)
        object.__setattr__(self, "mec_center", mc)
        object.__setattr__(self, "mec_radius", float(mr))

    @property
    def diameter(self) -> float:
        """Diameter of the minimum enclosing circle, m (obstacle size in eq. 4 / 15b)."""
        return 2.0 * self.mec_radius


@dataclass(frozen=True, eq=False, repr=False)
class World(CompactRepr):
    """Free space and obstacles.

    Parameters
    ----------
    free_space : array_like, shape (M, 2)
        Simple polygon (m) in which everything happens; its boundary is the walls.
    obstacles : sequence of Obstacle
        Each must lie strictly inside the free space, with unique ids, not overlapping.

    Raises
    ------
    InvalidInputError
        Malformed polygon.
    PlanningError
        An obstacle overlaps a wall or another obstacle, or two share an id.
    """

    free_space: np.ndarray
    obstacles: tuple[Obstacle, ...] = ()
    geometry: Polygon = field(init=False, repr=False)
    _width: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        pts = check_range(as_points(self.free_space, "free_space", min_count=3), "free_space",
                          MAX_SHEET_LENGTH, "m")
        geom = Polygon(pts)
        if not geom.is_valid or not geom.area > 0:
            raise InvalidInputError("free_space", "must be a simple polygon with positive "
                                                  "area (no self-intersections)")
        obs = require_instances(self.obstacles, Obstacle, "obstacles")
        seen: set[str] = set()
        for k, o in enumerate(obs):
            if not isinstance(o, Obstacle):
                raise InvalidInputError(f"obstacles[{k}]", "must be an Obstacle")
            if o.id in seen:
                raise PlanningError(f"obstacles[{k}].id", f"id {o.id!r} is used twice")
            seen.add(o.id)
            if not geom.contains(o.geometry):
                raise PlanningError(f"obstacles[{k}]", f"obstacle {o.id!r} overlaps the walls "
                                    "(it must lie strictly inside the free space)")
            for j in range(k):
                if obs[j].geometry.intersects(o.geometry):
                    raise PlanningError(f"obstacles[{k}]", f"obstacle {o.id!r} overlaps "
                                        f"obstacle {obs[j].id!r}")
        pts.setflags(write=False)
        object.__setattr__(self, "free_space", pts)
        object.__setattr__(self, "obstacles", obs)
        object.__setattr__(self, "geometry", geom)
        radius = shapely.maximum_inscribed_circle(
            geom, INSCRIBED_CIRCLE_RTOL * np.sqrt(geom.area)).length
        object.__setattr__(self, "_width", 2.0 * float(radius))

    def obstacle(self, oid: str) -> Obstacle:
        """The obstacle with this id.

        Raises
        ------
        UnknownObstacleError
            No obstacle has this id (also a ``KeyError``, as before).
        """
        for o in self.obstacles:
            if o.id == oid:
                return o
        known = ", ".join(repr(o.id) for o in self.obstacles) or "none"
        raise UnknownObstacleError("oid", f"no obstacle {oid!r} (known: {known})")

    @property
    def width(self) -> float:
        """A passage-width scale, m: twice the largest inscribed-circle radius of the free
        space (used only to normalise and bound the passable-area term of eq. 13)."""
        return self._width


#: Most robots of a planning team. The formation optimisation (eq. 15: SLSQP over 2N + 4
#: variables with N(N-1)/2 pair constraints, then forward kinematics over the taut sets)
#: grows steeply with N: about 1 s at 12 robots and a minute at 16 on a loaded 2-core
#: machine, and 148 s at 40 before answering. Larger teams are refused at once.
MAX_TEAM_ROBOTS = 12


@dataclass(frozen=True, eq=False)
class Team:
    """A sheet-carrying robot team (planning paper Sec. II-A and V-A).

    Parameters
    ----------
    carrier : SheetTeam
        The sheet (robot ``i`` holds vertex ``i``; metres), the holding height
        :math:`z_r` (m) and the object mass (kg, only for reporting tensions).
    robot_radius : float
        Radius of each robot's footprint, m (> 0).
    height_safety : float
        :math:`\\delta_h` of eq. (2): the object stays this far above any obstacle beneath
        the sheet, and above the ground, m (>= 0).
    lateral_safety : float
        Extra clearance between a robot's footprint and any obstacle or wall, m (>= 0).
        The paper's side safety distance of eqs. (1) and (4) is
        :math:`\\delta_s` = ``robot_radius + lateral_safety`` (its robots are particles).
    speed : float
        Constant translational speed of the formation, m/s (> 0).
    rotation_speed : float
        Constant rotation speed of the formation about the object, rad/s (> 0).

    Attributes
    ----------
    sheet : Sheet
        ``carrier.sheet``.
    hold_height : float
        ``carrier.hold_height``, m.
    mass : float or None
        ``carrier.mass``, kg.
    """

    carrier: SheetTeam
    robot_radius: float
    height_safety: float
    lateral_safety: float
    speed: float
    rotation_speed: float

    def __post_init__(self) -> None:
        if not isinstance(self.carrier, SheetTeam):
            raise InvalidInputError("carrier", "must be a taut.sheet.SheetTeam")
        if self.carrier.n > MAX_TEAM_ROBOTS:
            raise InvalidInputError("carrier", f"a planning team has at most "
                                               f"{MAX_TEAM_ROBOTS} robots, got {self.carrier.n}")
        for name, limit, unit, positive in (
                ("robot_radius", MAX_SHEET_LENGTH, "m", True),
                ("speed", MAX_SPEED, "m/s", True),
                ("rotation_speed", MAX_SPEED, "rad/s", True),
                ("height_safety", MAX_SHEET_LENGTH, "m", False),
                ("lateral_safety", MAX_SHEET_LENGTH, "m", False)):
            object.__setattr__(self, name, as_bounded(getattr(self, name), name, limit, unit,
                                                      positive=positive))

    @property
    def sheet(self) -> Sheet:
        """The sheet (``carrier.sheet``)."""
        return self.carrier.sheet

    @property
    def hold_height(self) -> float:
        """Holding height :math:`z_r`, m (``carrier.hold_height``)."""
        return self.carrier.hold_height

    @property
    def mass(self) -> float | None:
        """Object mass, kg (``carrier.mass``)."""
        return self.carrier.mass

    @property
    def n(self) -> int:
        """Number of robots."""
        return self.carrier.n

    @property
    def clearance(self) -> float:
        """Least distance from a robot's centre to any obstacle or wall, m: robot radius
        plus lateral safety, the side safety distance :math:`\\delta_s` of eqs. (1) and
        (4)."""
        return self.robot_radius + self.lateral_safety


@dataclass(frozen=True, eq=False, repr=False)
class Scenario(CompactRepr):
    """A planning problem: move the object's projection from ``start`` to ``goal``.

    Raises
    ------
    PlanningError
        Start or goal outside the free space or inside (or on) an obstacle.
    """

    world: World
    team: Team
    start: np.ndarray
    goal: np.ndarray
    name: str | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.world, World):
            raise InvalidInputError("world", "must be a World")
        if not isinstance(self.team, Team):
            raise InvalidInputError("team", "must be a Team")
        for name in ("start", "goal"):
            p = as_array(getattr(self, name), name, shape=(2,))
            pt = Point(p)
            if not self.world.geometry.contains(pt):
                raise PlanningError(name, f"({p[0]:.6g}, {p[1]:.6g}) is outside the free "
                                    "space")
            for o in self.world.obstacles:
                if o.geometry.intersects(pt):
                    raise PlanningError(name, f"({p[0]:.6g}, {p[1]:.6g}) is inside obstacle "
                                        f"{o.id!r}")
            p.setflags(write=False)
            object.__setattr__(self, name, p)
