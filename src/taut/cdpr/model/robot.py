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
from typing import Any

import numpy as np

from ..._units import GRAVITY
from ..._validate import MAX_CABLES, MAX_TENSION_N, as_array, as_finite_scalar, check_range
from ...errors import InvalidModelError
from .footprint import check_footprint
from .parts import Base, Cable, Payload, Platform
from ..._validate import as_flag, require_instance, require_instances
from ..._repr import CompactRepr

__all__ = ["Base", "Platform", "Payload", "Cable", "CableRobot", "check_footprint",
           "with_stabilisers", "with_friction", "with_base_acceleration"]


@dataclass(frozen=True, eq=False, repr=False)
class CableRobot(CompactRepr):
    """A validated cable-driven parallel robot (fixed or on mobile bases).

    Parameters
    ----------
    bases : sequence of Base
    platform : Platform
    cables : sequence of Cable
        Cable order defines the column order of the wrench matrix ``W`` (FASTKIT eq. 18);
        at most :data:`taut._validate.MAX_CABLES`.
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
        :func:`taut.cdpr.workspace.exit_box.platform_inside_exits` and, when True, a fourth
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
        ``u_Cj . ((g - c_j) x w_g)``: moment of the base weight about each edge, N m (< 0
        at rest), with ``g`` the base centre of mass and ``w_g = m_b (g_vec - a_b)``: the
        weight plus the d'Alembert force of the base's own acceleration ``a_b``
        (:attr:`Base.acceleration`, zero unless the base drives).
    """

    bases: tuple[Base, ...]
    platform: Platform
    cables: tuple[Cable, ...]
    payload: Payload = field(default_factory=Payload)
    gravity: Any = (0.0, 0.0, -GRAVITY)
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
        s(self, "bases", require_instances(self.bases, Base, "bases"))
        s(self, "cables", require_instances(self.cables, Cable, "cables"))
        require_instance(self.platform, Platform, "platform")
        require_instance(self.payload, Payload, "payload")
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
        if m > MAX_CABLES:
            raise InvalidModelError("cables", f"{m} cables exceed the accepted range "
                                              f"{MAX_CABLES} cables")
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
            wg = base.mass * base.effective_gravity(g)      # weight + d'Alembert force
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
    require_instance(robot, CableRobot, "robot")
    from dataclasses import replace
    bases = tuple(replace(b, exit_points=dict(b.exit_points), friction=friction,
                          friction_sides=b.friction_sides if sides is None else sides)
                  if b.mobile else b for b in robot.bases)
    return replace(robot, bases=bases)


def with_stabilisers(robot: CableRobot, *, deployed: bool = True) -> CableRobot:
    """The same robot with the stabilisers of every mobile base that has them deployed
    (or retracted). Deployed stabilisers replace the support polygon by the convex hull of
    wheels and stabiliser feet, so tipping limits can only get looser."""
    require_instance(robot, CableRobot, "robot")
    deployed = as_flag(deployed, "deployed")
    from dataclasses import replace
    bases = tuple(replace(b, exit_points=dict(b.exit_points),
                          stabilisers_deployed=bool(deployed and b.stabilisers is not None))
                  if b.mobile else b for b in robot.bases)
    return replace(robot, bases=bases)


def with_base_acceleration(robot: CableRobot, acceleration: Any) -> CableRobot:
    """The same robot with every mobile base accelerating at ``acceleration`` (3,) m/s^2,
    world frame (coupled bases translating together, e.g. navigation mode; rotation
    neglected), or base ``k`` at row ``k`` of a (K, 3) array (one base driving in task mode):
    their d'Alembert forces enter tipping and sliding (:attr:`Base.acceleration`).

    Examples
    --------
    >>> from taut.io.cdpr_model import load_cdpr_model
    >>> robot = load_cdpr_model("fastkit")
    >>> a = with_base_acceleration(robot, [0.25, 0, 0])
    >>> bool((a.edge_weight_moment != robot.edge_weight_moment).any())
    True
    """
    require_instance(robot, CableRobot, "robot")
    acc = as_array(acceleration, "acceleration")
    if acc.shape == (3,):
        acc = np.tile(acc, (len(robot.bases), 1))
    acc = as_array(acc, "acceleration", shape=(len(robot.bases), 3))
    from dataclasses import replace
    bases = tuple(replace(b, exit_points=dict(b.exit_points), acceleration=a)
                  if b.mobile else b for b, a in zip(robot.bases, acc))
    return replace(robot, bases=bases)
