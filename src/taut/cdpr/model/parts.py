"""The parts of a cable-driven parallel robot model: bases, platform, payload, cables.

Immutable and validated when built (see :mod:`taut.cdpr.model.robot`, which assembles them into
a :class:`~taut.cdpr.model.robot.CableRobot`, for the frames and units). SI units: m, kg, N, rad.
Every constructor raises :class:`taut.errors.InvalidModelError` (or
:class:`taut.errors.InvalidInputError` for a malformed number) naming the field.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

from ..._geometry import convex_hull_2d as _convex_hull_2d
from ..._validate import MAX_ACCELERATION, as_array, as_finite_scalar, as_points, check_range
from ...errors import InvalidModelError
from .._tol import INERTIA_REL
from .footprint import check_footprint
from .footprint import inside_convex as _inside_convex
from ..._repr import CompactRepr

__all__ = ["Base", "Platform", "Payload", "Cable"]


def _rot_z(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _named_points(points: Mapping[str, Any], fld: str) -> tuple[tuple[str, ...], np.ndarray]:
    if not isinstance(points, Mapping) or len(points) == 0:
        raise InvalidModelError(fld, "must be a non-empty mapping of point names to [x, y, z]")
    names = tuple(str(k) for k in points)
    arr = np.stack([as_array(points[k], f"{fld}.{k}", shape=(3,)) for k in points])
    return names, arr


@dataclass(frozen=True, eq=False, repr=False)
class Base(CompactRepr):
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
        See :mod:`taut.cdpr.statics.sliding`.
    friction_sides : int
        Number of faces (>= 3) of the linearised friction pyramid (inscribed in the cone,
        so conservative by at most ``1 - cos(pi / friction_sides)``; default 8: 7.6 %).
    acceleration : (3,), default (0, 0, 0)
        Translational acceleration of a mobile base in the world frame, m/s^2 (a base
        driving: navigation, or the active base moving in task mode). Its d'Alembert force
        ``-mass * acceleration`` acts at ``com`` and enters the tipping moments (FASTKIT
        eqs. 21-23, :attr:`CableRobot.edge_weight_moment`) and the sliding condition with
        the weight, i.e. the base feels the effective gravity ``g - acceleration``.
        Ignored for a fixed frame.
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
    acceleration: Any = (0.0, 0.0, 0.0)
    exit_names: tuple[str, ...] = field(init=False)
    exit_local: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        f = f"bases[{self.name}]"
        if not isinstance(self.mobile, (bool, np.bool_)):
            raise InvalidModelError(f"{f}.mobile", "must be True or False, got "
                                                   f"{type(self.mobile).__name__}")
        object.__setattr__(self, "mobile", bool(self.mobile))
        names, pts = _named_points(self.exit_points, f"{f}.exit_points")
        object.__setattr__(self, "exit_names", names)
        object.__setattr__(self, "exit_local", pts)
        object.__setattr__(self, "exit_points", MappingProxyType(dict(zip(names, pts))))
        object.__setattr__(self, "pose", as_array(self.pose, f"{f}.pose", shape=(3,)))
        object.__setattr__(self, "com", as_array(self.com, f"{f}.com", shape=(3,)))
        object.__setattr__(self, "acceleration", check_range(
            as_array(self.acceleration, f"{f}.acceleration", shape=(3,)),
            f"{f}.acceleration", MAX_ACCELERATION, "m/s^2"))
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

    def effective_gravity(self, gravity: np.ndarray) -> np.ndarray:
        """``gravity - acceleration`` (3,), m/s^2: the base's weight and its d'Alembert
        inertial force together are ``mass * effective_gravity(g)`` at ``com``."""
        return np.asarray(gravity, dtype=float) - self.acceleration

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


@dataclass(frozen=True, eq=False, repr=False)
class Platform(CompactRepr):
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
        inertia = _inertia_matrix(self.inertia, "platform.inertia")
        object.__setattr__(self, "inertia", inertia)


@dataclass(frozen=True, eq=False)
class Payload:
    """A payload rigidly held by the platform: mass (kg, >= 0), centre of mass in the
    platform frame (m) and inertia about that centre of mass in the platform frame (kg m^2,
    3 numbers or 3x3; default zero: a point mass). Statics use mass and centre of mass; the
    control simulation's rigid body adds the inertia."""

    mass: float = 0.0
    com: Any = (0.0, 0.0, 0.0)
    inertia: Any = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))

    def __post_init__(self) -> None:
        m = as_finite_scalar(self.mass, "payload.mass")
        if m < 0:
            raise InvalidModelError("payload.mass", f"must be non-negative, got {m:g}")
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", as_array(self.com, "payload.com", shape=(3,)))
        object.__setattr__(self, "inertia", _inertia_matrix(self.inertia, "payload.inertia"))


def _inertia_matrix(value: Any, field: str) -> np.ndarray:
    """A symmetric positive semi-definite 3x3 inertia (kg m^2) from 3 numbers (principal
    moments) or a 3x3 matrix."""
    inertia = as_array(value, field)
    if inertia.shape == (3,):
        inertia = np.diag(inertia)
    if inertia.shape != (3, 3):
        raise InvalidModelError(field, "must be 3 numbers or a 3x3 matrix")
    if not np.allclose(inertia, inertia.T, atol=INERTIA_REL * (1 + np.abs(inertia).max())):
        raise InvalidModelError(field, "must be symmetric")
    if np.linalg.eigvalsh(inertia).min() < -INERTIA_REL * (1 + np.abs(inertia).max()):
        raise InvalidModelError(field, "must be positive semi-definite")
    return inertia


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
