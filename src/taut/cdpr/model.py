"""Immutable, validated models of cable-driven parallel robots (CDPRs) on fixed frames or
mobile bases, after the FASTKIT paper (Rasheed et al., "FASTKIT: a mobile cable-driven
parallel robot for logistics", §3-4).

Units are SI throughout: metres, kilograms, newtons, radians. The world frame has its z
axis up and the ground at ``z = 0``. A base pose is ``(x, y, theta)``: the base frame is
the world frame rotated by ``theta`` about z and moved to ``(x, y, 0)``. Exit points,
footprints and the base centre of mass are given in the base frame; attachment points and
the platform/payload centres of mass in the platform frame.

Every constructor checks its inputs and raises :class:`taut.errors.InvalidModelError`
(or :class:`taut.errors.InvalidInputError` for a malformed number) naming the field.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from .._validate import MAX_TENSION_N, as_array, as_finite_scalar, as_points, check_range
from ..errors import InvalidModelError
from ._tol import INERTIA_REL
from .footprint import check_footprint
from .footprint import convex_hull_2d as _convex_hull_2d
from .footprint import inside_convex as _inside_convex

__all__ = ["Base", "Platform", "Payload", "Cable", "CableRobot", "check_footprint",
           "with_stabilisers", "with_friction"]


def _rot_z(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _named_points(points: Mapping[str, Any], fld: str) -> tuple[tuple[str, ...], np.ndarray]:
    if not isinstance(points, Mapping) or len(points) == 0:
        raise InvalidModelError(fld, "must be a non-empty mapping of point names to [x, y, z]")
    names = tuple(str(k) for k in points)
    arr = np.stack([as_array(points[k], f"{fld}.{k}", shape=(3,)) for k in points])
    return names, arr


@dataclass(frozen=True, eq=False)
class Base:
    """A cable robot base: a fixed frame or a mobile base carrying cable exit points.

    Parameters
    ----------
    name : str
    exit_points : mapping str -> (3,)
        Cable exit (pulley) points in the base frame, m.
    pose : (3,), default (0, 0, 0)
        ``(x, y, theta)`` of the base frame in the world, m and rad.
    mobile : bool
        True for a base that can tip (FASTKIT's mobile bases); False for a frame bolted to
        the ground (no tipping constraints).
    mass : float
        Base mass, kg (> 0 when ``mobile``).
    com : (3,)
        Base centre of mass in the base frame, m.
    footprint : (p, 2)
        Wheel contact polygon in the base frame (convex, either orientation), m.
    stabilisers : (q, 2) or None
        Contact points of the stabiliser feet in the base frame, m.
    stabilisers_deployed : bool
        When True the support polygon is the convex hull of the wheels and stabilisers.
    friction : float or None
        Coulomb friction coefficient (dimensionless, >= 0) between the ground and the
        wheels / stabiliser feet of a mobile base; None (default) does not model sliding.
        See :mod:`taut.cdpr.sliding`.
    friction_sides : int
        Number of faces (>= 3) of the linearised friction pyramid (inscribed in the cone,
        so conservative by at most ``1 - cos(pi / friction_sides)``; default 8: 7.6 %).
    """

    name: str
    exit_points: Mapping[str, Any]
    pose: Any = (0.0, 0.0, 0.0)
    mobile: bool = False
    mass: float = 0.0
    com: Any = (0.0, 0.0, 0.0)
    footprint: Any = None
    stabilisers: Any = None
    stabilisers_deployed: bool = False
    friction: float | None = None
    friction_sides: int = 8
    exit_names: tuple[str, ...] = field(init=False)
    exit_local: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        f = f"bases[{self.name}]"
        names, pts = _named_points(self.exit_points, f"{f}.exit_points")
        object.__setattr__(self, "exit_names", names)
        object.__setattr__(self, "exit_local", pts)
        object.__setattr__(self, "exit_points", MappingProxyType(dict(zip(names, pts))))
        object.__setattr__(self, "pose", as_array(self.pose, f"{f}.pose", shape=(3,)))
        object.__setattr__(self, "com", as_array(self.com, f"{f}.com", shape=(3,)))
        object.__setattr__(self, "mass", as_finite_scalar(self.mass, f"{f}.mass"))
        if self.friction is not None:
            mu = as_finite_scalar(self.friction, f"{f}.friction")
            if mu < 0:
                raise InvalidModelError(f"{f}.friction", f"must be non-negative, got {mu:g}")
            object.__setattr__(self, "friction", mu)
        sides = self.friction_sides
        if isinstance(sides, bool) or not isinstance(sides, (int, np.integer)) or sides < 3:
            raise InvalidModelError(f"{f}.friction_sides", "must be an integer >= 3")
        if not self.mobile:
            return
        if not self.mass > 0:
            raise InvalidModelError(f"{f}.mass", "a mobile base needs a positive mass")
        if self.footprint is None:
            raise InvalidModelError(f"{f}.footprint", "a mobile base needs a footprint")
        fp = check_footprint(self.footprint, f"{f}.footprint")
        object.__setattr__(self, "footprint", fp)
        if self.stabilisers is not None:
            st = as_points(self.stabilisers, f"{f}.stabilisers", dim=2, min_count=1)
            object.__setattr__(self, "stabilisers", st)
        elif self.stabilisers_deployed:
            raise InvalidModelError(f"{f}.stabilisers", "deployed but no stabiliser points")
        if not _inside_convex(fp, self.com[:2]):
            raise InvalidModelError(f"{f}.com", "centre of mass lies outside the wheel "
                                                "footprint: the base tips over unloaded")

    @property
    def rotation(self) -> np.ndarray:
        """(3, 3) rotation of the base frame in the world."""
        return _rot_z(float(self.pose[2]))

    def to_world(self, local: np.ndarray) -> np.ndarray:
        """Map base-frame points ``(..., 3)`` to world coordinates, m."""
        return local @ self.rotation.T + np.array([self.pose[0], self.pose[1], 0.0])

    def support_world(self) -> np.ndarray:
        """(p, 3) support polygon in the world (z = 0), counter-clockwise; (0, 3) for a
        fixed frame."""
        poly = self.support_polygon
        if poly is None:
            return np.zeros((0, 3))
        return self.to_world(np.column_stack([poly, np.zeros(len(poly))]))

    @property
    def support_polygon(self) -> np.ndarray | None:
        """(p, 2) counter-clockwise support polygon in the base frame (None when fixed)."""
        if not self.mobile:
            return None
        if self.stabilisers_deployed and self.stabilisers is not None:
            return _convex_hull_2d(np.vstack([self.footprint, self.stabilisers]))
        return self.footprint


@dataclass(frozen=True, eq=False)
class Platform:
    """The moving platform.

    Parameters
    ----------
    attachment_points : mapping str -> (3,)
        Cable attachment points in the platform frame, m. The platform reference point P
        (the pose position) is the platform-frame origin. When every attachment point is
        the origin the platform is a point mass and the robot has 3 degrees of freedom.
    mass : float
        kg, >= 0.
    com : (3,)
        Centre of mass in the platform frame, m.
    inertia : (3, 3) or (3,)
        Inertia about the centre of mass (kg m^2); a diagonal may be given as 3 numbers.
        Stored for completeness; the statics here do not use it.
    """

    attachment_points: Mapping[str, Any]
    mass: float = 0.0
    com: Any = (0.0, 0.0, 0.0)
    inertia: Any = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    attach_names: tuple[str, ...] = field(init=False)
    attach_local: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        names, pts = _named_points(self.attachment_points, "platform.attachment_points")
        object.__setattr__(self, "attach_names", names)
        object.__setattr__(self, "attach_local", pts)
        object.__setattr__(self, "attachment_points", MappingProxyType(dict(zip(names, pts))))
        m = as_finite_scalar(self.mass, "platform.mass")
        if m < 0:
            raise InvalidModelError("platform.mass", f"must be non-negative, got {m:g}")
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", as_array(self.com, "platform.com", shape=(3,)))
        inertia = as_array(self.inertia, "platform.inertia")
        if inertia.shape == (3,):
            inertia = np.diag(inertia)
        if inertia.shape != (3, 3):
            raise InvalidModelError("platform.inertia", "must be 3 numbers or a 3x3 matrix")
        if not np.allclose(inertia, inertia.T, atol=INERTIA_REL * (1 + np.abs(inertia).max())):
            raise InvalidModelError("platform.inertia", "must be symmetric")
        if np.linalg.eigvalsh(inertia).min() < -INERTIA_REL * (1 + np.abs(inertia).max()):
            raise InvalidModelError("platform.inertia", "must be positive semi-definite")
        object.__setattr__(self, "inertia", inertia)


@dataclass(frozen=True, eq=False)
class Payload:
    """A payload rigidly held by the platform: mass (kg, >= 0) and centre of mass in the
    platform frame (m)."""

    mass: float = 0.0
    com: Any = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        m = as_finite_scalar(self.mass, "payload.mass")
        if m < 0:
            raise InvalidModelError("payload.mass", f"must be non-negative, got {m:g}")
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", as_array(self.com, "payload.com", shape=(3,)))


@dataclass(frozen=True)
class Cable:
    """A cable from exit point ``exit`` of base ``base`` to platform attachment point
    ``attachment``, with tension limits ``t_min <= t <= t_max`` in N (FASTKIT eq. 20)."""

    name: str
    base: str
    exit: str
    attachment: str
    t_min: float
    t_max: float


@dataclass(frozen=True, eq=False)
class CableRobot:
    """A validated cable-driven parallel robot (fixed or on mobile bases).

    Parameters
    ----------
    bases : sequence of Base
    platform : Platform
    cables : sequence of Cable
        Cable order defines the column order of the wrench matrix ``W`` (FASTKIT eq. 18).
    payload : Payload, optional
    gravity : (3,), default (0, 0, -9.81)
        Gravity acceleration, m/s^2.
    bounds : (2, 3), optional
        ``[lower, upper]`` corners of the box the platform position must stay in, m.
        Default: the bounding box of all exit points, from the ground (z = 0) up.
    desired_workspace : (2, 3), optional
        ``[lower, upper]`` corners of the desired workspace, m (a flat box is a slice).
    name : str
    platform_inside_exits : bool, default False
        Whether the whole platform (the box of its attachment points) must stay inside the
        exits' bounding box from the ground up; checked by
        :func:`taut.cdpr.exit_box.platform_inside_exits` and, when True, a fourth
        workspace condition (``"exits_box"``).

    Attributes
    ----------
    m : int
        Number of cables.
    dof : int
        6, or 3 for a point-mass platform (all attachment points at the origin).
    exits_world : ndarray (m, 3)
        Exit points in the world, m.
    attach_local : ndarray (m, 3)
        Attachment point of each cable in the platform frame, m.
    t_min, t_max : ndarray (m,)
        Tension limits, N.
    cable_base : ndarray (m,) of int
        Index of each cable's base.
    edge_points, edge_dirs : ndarray (E, 3)
        Start point and unit direction of every support-polygon edge of every mobile base,
        world frame, counter-clockwise (FASTKIT's ``c_j`` and ``u_Cj``).
    edge_base : ndarray (E,) of int
    edge_weight_moment : ndarray (E,)
        ``u_Cj . ((g - c_j) x w_g)``: moment of the base weight about each edge, N m (< 0).
    """

    bases: tuple[Base, ...]
    platform: Platform
    cables: tuple[Cable, ...]
    payload: Payload = field(default_factory=Payload)
    gravity: Any = (0.0, 0.0, -9.81)
    bounds: Any = None
    desired_workspace: Any = None
    name: str = "cable robot"
    platform_inside_exits: bool = False
    # Derived fields, filled by __post_init__ (declared so that type checkers see them).
    m: int = field(init=False)
    dof: int = field(init=False)
    exits_world: np.ndarray = field(init=False, repr=False)
    attach_local: np.ndarray = field(init=False, repr=False)
    t_min: np.ndarray = field(init=False, repr=False)
    t_max: np.ndarray = field(init=False, repr=False)
    cable_base: np.ndarray = field(init=False, repr=False)
    edge_points: np.ndarray = field(init=False, repr=False)
    edge_dirs: np.ndarray = field(init=False, repr=False)
    edge_base: np.ndarray = field(init=False, repr=False)
    edge_weight_moment: np.ndarray = field(init=False, repr=False)
    _tip_V: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "bases", tuple(self.bases))
        s(self, "cables", tuple(self.cables))
        if not self.bases:
            raise InvalidModelError("bases", "at least one base is required")
        names = [b.name for b in self.bases]
        if len(set(names)) != len(names):
            raise InvalidModelError("bases", "base names must be unique")
        s(self, "gravity", as_array(self.gravity, "gravity", shape=(3,)))
        base_idx = {b.name: i for i, b in enumerate(self.bases)}
        att_idx = {n: i for i, n in enumerate(self.platform.attach_names)}
        m = len(self.cables)
        if m == 0:
            raise InvalidModelError("cables", "at least one cable is required")
        exits = np.empty((m, 3))
        attach = np.empty((m, 3))
        tmin = np.empty(m)
        tmax = np.empty(m)
        cb = np.empty(m, dtype=np.intp)
        seen: set[tuple[str, str]] = set()
        for i, c in enumerate(self.cables):
            f = f"cables[{i}]"
            if c.base not in base_idx:
                raise InvalidModelError(f"{f}.exit", f"no base named {c.base!r}")
            base = self.bases[base_idx[c.base]]
            if c.exit not in base.exit_points:
                raise InvalidModelError(f"{f}.exit",
                                        f"no exit point {c.exit!r} on base {c.base!r}")
            if c.attachment not in att_idx:
                raise InvalidModelError(f"{f}.attachment",
                                        f"no attachment point {c.attachment!r} on the platform")
            if (c.base, c.exit) in seen:
                raise InvalidModelError(f"{f}.exit", f"exit point {c.base}.{c.exit} is "
                                                     "used by two cables")
            seen.add((c.base, c.exit))
            lo = as_finite_scalar(c.t_min, f"{f}.t_min")
            hi = as_finite_scalar(c.t_max, f"{f}.t_max")
            check_range(hi, f"{f}.t_max", MAX_TENSION_N, "N")
            if lo < 0:
                raise InvalidModelError(f"{f}.t_min", f"cables cannot push: {lo:g} N < 0")
            if not hi > lo:
                raise InvalidModelError(f"{f}.t_min", f"minimum tension {lo:g} N is not "
                                                      f"below maximum {hi:g} N")
            exits[i] = base.to_world(base.exit_points[c.exit])
            attach[i] = self.platform.attachment_points[c.attachment]
            tmin[i], tmax[i] = lo, hi
            cb[i] = base_idx[c.base]
        s(self, "m", m)
        s(self, "exits_world", exits)
        s(self, "attach_local", attach)
        s(self, "t_min", tmin)
        s(self, "t_max", tmax)
        s(self, "cable_base", cb)
        if np.all(np.abs(self.platform.attach_local) == 0.0):
            s(self, "dof", 3)
        elif np.ptp(self.platform.attach_local, axis=0).max() == 0.0:
            raise InvalidModelError("platform.attachment_points", "all attachment points "
                                    "coincide away from the origin; put them at the origin "
                                    "for a point-mass platform")
        else:
            s(self, "dof", 6)
        if m < self.dof:
            raise InvalidModelError("cables", f"{m} cables cannot balance a {self.dof}-DoF "
                                              "platform")
        self._set_boxes(exits)
        self._build_tipping()

    def _set_boxes(self, exits: np.ndarray) -> None:
        """Frame bounds (default: the exits' bounding box from the ground up) and the
        desired workspace, validated."""
        s = object.__setattr__
        if self.bounds is None:
            lo = exits.min(axis=0)
            hi = exits.max(axis=0)
            lo[2] = min(0.0, lo[2])
            box = np.stack([lo, hi])
        else:
            box = as_array(self.bounds, "bounds", shape=(2, 3))
        if np.any(box[1] < box[0]):
            raise InvalidModelError("bounds", "lower corner above upper corner")
        s(self, "bounds", box)
        if self.desired_workspace is not None:
            dw = as_array(self.desired_workspace, "desired_workspace", shape=(2, 3))
            if np.any(dw[1] < dw[0]):
                raise InvalidModelError("desired_workspace", "lower corner above upper corner")
            s(self, "desired_workspace", dw)

    def _build_tipping(self) -> None:
        pts, dirs, eb, m0 = [], [], [], []
        g = self.gravity
        for k, base in enumerate(self.bases):
            poly = base.support_polygon
            if poly is None:
                continue
            c = base.to_world(np.column_stack([poly, np.zeros(len(poly))]))
            d = np.roll(c, -1, axis=0) - c
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            com = base.to_world(base.com)
            wg = base.mass * g
            pts.append(c)
            dirs.append(d)
            eb.append(np.full(len(c), k))
            m0.append(np.einsum("ij,ij->i", d, np.cross(com - c, wg)))
        s = object.__setattr__
        if pts:
            s(self, "edge_points", np.vstack(pts))
            s(self, "edge_dirs", np.vstack(dirs))
            s(self, "edge_base", np.concatenate(eb))
            s(self, "edge_weight_moment", np.concatenate(m0))
        else:
            s(self, "edge_points", np.zeros((0, 3)))
            s(self, "edge_dirs", np.zeros((0, 3)))
            s(self, "edge_base", np.zeros(0, dtype=np.intp))
            s(self, "edge_weight_moment", np.zeros(0))
        # Constant part of the tipping coefficients: T[j, i] = u_i . V[j, i] with
        # V[j, i] = u_Cj x (c_j - b_i) for cables on edge j's base, 0 otherwise.
        V = np.cross(self.edge_dirs[:, None, :],
                     self.edge_points[:, None, :] - self.exits_world[None, :, :])
        V *= (self.edge_base[:, None] == self.cable_base[None, :])[:, :, None]
        s(self, "_tip_V", V)

    @property
    def n_edges(self) -> int:
        """Number of tipping constraints (support-polygon edges of all mobile bases)."""
        return int(self.edge_points.shape[0])

    @property
    def has_tipping(self) -> bool:
        """True when at least one base is mobile."""
        return self.n_edges > 0

    @property
    def has_sliding(self) -> bool:
        """True when at least one mobile base has a friction coefficient."""
        return any(b.mobile and b.friction is not None for b in self.bases)

    @property
    def total_mass(self) -> float:
        """Platform plus payload mass, kg."""
        return self.platform.mass + self.payload.mass

    def describe(self) -> dict[str, Any]:
        """A JSON-friendly summary."""
        return {"name": self.name, "cables": self.m, "dof": self.dof,
                "bases": [{"name": b.name, "mobile": b.mobile, "pose": b.pose.tolist(),
                           "stabilisers_deployed": b.stabilisers_deployed}
                          for b in self.bases],
                "moving_mass_kg": self.total_mass}


def with_friction(robot: CableRobot, friction: float | None,
                  sides: int | None = None) -> CableRobot:
    """The same robot with ground friction coefficient ``friction`` (dimensionless) on every
    mobile base (None: sliding not modelled), and optionally ``sides`` faces of the
    linearised friction pyramid.

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> [b.friction for b in with_friction(load_cdpr_model("fastkit"), 0.3).bases]
    [0.3, 0.3]
    """
    from dataclasses import replace
    bases = tuple(replace(b, exit_points=dict(b.exit_points), friction=friction,
                          friction_sides=b.friction_sides if sides is None else sides)
                  if b.mobile else b for b in robot.bases)
    return replace(robot, bases=bases)


def with_stabilisers(robot: CableRobot, deployed: bool = True) -> CableRobot:
    """The same robot with the stabilisers of every mobile base that has them deployed
    (or retracted). Deployed stabilisers replace the support polygon by the convex hull of
    wheels and stabiliser feet, so tipping limits can only get looser."""
    from dataclasses import replace
    bases = tuple(replace(b, exit_points=dict(b.exit_points),
                          stabilisers_deployed=bool(deployed and b.stabilisers is not None))
                  if b.mobile else b for b in robot.bases)
    return replace(robot, bases=bases)
