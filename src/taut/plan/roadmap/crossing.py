"""Local crossing motion (planning paper Sec. IV-B, Algorithm 2) and time parametrisation of
a whole route.

A crossing leg runs straight from ``a`` through the obstacle's centre ``o`` to ``b`` in the
direction :math:`\\mathbf{u}`. Following Algorithm 2, with constant speeds:

1. :math:`t_0 \\to t_1`: rotate the formation about the object's projection so the entering
   side's ray (:func:`~taut.plan.formations.optimal.crossing_pairs`) points along
   :math:`\\mathbf{u}` (the side faces the obstacle);
2. :math:`t_1 \\to t_2`: translate from ``a`` until the object is above ``o``;
3. :math:`t_2 \\to t_3`: rotate by the relative angle :math:`\\Delta` so the exiting side's
   ray points along :math:`-\\mathbf{u}` (the obstacle, still under the object, stays at
   least the clearance from every robot, which the side test guarantees);
4. :math:`t_3 \\to t_4`: translate to ``b``: the obstacle leaves through the exiting side.

Straight offset crossings (our extension, :func:`~taut.plan.formations.optimal.offset_crossings`):
rotate to an admissible heading (the one needing the least turn), then translate across; the obstacle passes under the sheet
between two robots without passing under the object, and no turn is needed on the way.

Formation changes (``"reform"`` legs) happen in place: the robots move straight from one
formation to the other at the team's speed; the object's planned states there are the
forward-kinematics equilibria followed continuously from the previous sample.

The paper rotates about the formation centroid; we rotate about the object's projection,
so the object passes exactly over the obstacle's centre and start/goal are object
positions. Times follow from distances and the team's speeds. Plain legs translate at
constant heading.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _tol
from ..formations.optimal import Formation, _crossing_pairs, _offset_crossings
from ...sheet import forward_kinematics
from .route import Leg, Route
from ..world import Scenario
from ..._validate import require_instance, require_instances
from ..._repr import CompactRepr

__all__ = ["CrossingRecord", "Motion", "motion_from_legs"]

#: Largest translation between samples, m.
STEP = 0.04
#: Largest arc (m) any robot sweeps between samples while rotating.
TURN_STEP = 0.04


def _wrap(a: float) -> float:
    return float(np.angle(np.exp(1j * a)))


@dataclass(frozen=True, eq=False, repr=False)
class CrossingRecord(CompactRepr):
    """One execution of Algorithm 2.

    Attributes
    ----------
    obstacle : str
    times : ndarray, shape (5,)
        :math:`t_0 \\dots t_4`, s.
    direction : float
        Travel direction :math:`\\mathbf{u}` (rad, world frame).
    entering, exiting : float
        Ray directions of the entering and exiting sides in the formation frame, rad.
    turn : float
        :math:`\\Delta` of step 3, rad (counter-clockwise positive).
    kind : {"algorithm2", "straight"}
        The paper's four steps, or a straight offset crossing (no turn; ``times[2] ==
        times[3]`` is the moment of closest approach).
    """

    obstacle: str
    times: np.ndarray
    direction: float
    entering: float
    exiting: float
    turn: float
    kind: str = "algorithm2"


@dataclass(frozen=True, eq=False, repr=False)
class Motion(CompactRepr):
    """Sampled motion of the team.

    Attributes
    ----------
    times : ndarray, shape (T,)
        s, increasing from 0.
    center : ndarray, shape (T, 2)
        Object projection, m (named as :attr:`Obstacle.center <taut.plan.Obstacle>`).
    heading : ndarray, shape (T,)
        Formation rotation, rad (unwrapped).
    robots : ndarray, shape (T, N, 2)
    object : ndarray, shape (T, 3)
        Planned object position (rigid formation), m.
    crossings : tuple of CrossingRecord
    """

    times: np.ndarray
    center: np.ndarray
    heading: np.ndarray
    robots: np.ndarray
    object: np.ndarray
    crossings: tuple[CrossingRecord, ...]

    @property
    def duration(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0

    @property
    def path_length(self) -> float:
        """Planar length of the object's path, m."""
        return float(np.linalg.norm(np.diff(self.center, axis=0), axis=1).sum())


class _Builder:
    def __init__(self, formation: Formation, speed: float, omega: float, start: np.ndarray):
        self.f, self.v, self.w = formation, speed, omega
        self.t, self.c, self.h = [0.0], [np.asarray(start, float)], [0.0]
        self.robots = [formation.placed(self.c[0], 0.0)]
        self.z = [formation.object_height]          # NaN: fixed later by the model

    def _push(self, t: np.ndarray, c: np.ndarray, h: np.ndarray) -> None:
        self.t.extend(t)
        self.c.extend(c)
        self.h.extend(h)
        self.robots.extend(self.f.placed(np.asarray(c), np.asarray(h)))
        self.z.extend([self.f.object_height] * len(t))

    def translate(self, to: np.ndarray) -> None:
        a = self.c[-1]
        dist = float(np.linalg.norm(to - a))
        if dist <= 0.0:
            return
        k = max(1, int(np.ceil(dist / STEP)))
        s = np.arange(1, k + 1) / k
        self._push(self.t[-1] + s * dist / self.v, a + s[:, None] * (to - a),
                   np.full(k, self.h[-1]))

    def rotate(self, by: float) -> None:
        if by == 0.0:
            return
        radius = float(np.linalg.norm(self.f.robots, axis=1).max())
        k = max(1, int(np.ceil(abs(by) * radius / TURN_STEP)))
        s = np.arange(1, k + 1) / k
        self._push(self.t[-1] + s * abs(by) / self.w, np.repeat(self.c[-1][None], k, axis=0),
                   self.h[-1] + s * by)

    def reform(self, new: Formation) -> None:
        """Robots move straight from the current formation to ``new`` (same object
        projection and heading) at the team's speed."""
        a = self.robots[-1]
        b = new.placed(self.c[-1], self.h[-1])
        dist = float(np.linalg.norm(b - a, axis=1).max())
        self.f = new
        if dist <= 0.0:
            return
        k = max(1, int(np.ceil(dist / STEP)))
        s = np.arange(1, k + 1) / k
        self.t.extend(self.t[-1] + s * dist / self.v)
        self.c.extend([self.c[-1]] * k)
        self.h.extend([self.h[-1]] * k)
        self.robots.extend(a + s[:, None, None] * (b - a))
        self.z.extend([np.nan] * (k - 1) + [new.object_height])


def _fill_reforms(scenario: Scenario, robots: np.ndarray, obj: np.ndarray) -> None:
    """Planned object during formation changes: follow the stable equilibrium of forward
    kinematics nearest to the previous state, sample by sample (in place)."""
    team = scenario.team
    for t in np.flatnonzero(np.isnan(obj[:, 2])):
        fk = forward_kinematics(team.carrier, robots[t])
        if not fk.stable:
            return                              # verification will reject the plan
        prev = obj[t - 1]
        obj[t] = min((e.object for e in fk.stable), key=lambda p: float(np.linalg.norm(p - prev)))


def _straight_heading(f: Formation, clearance: float, direction: float, offset: np.ndarray,
                      current: float, fallback: float) -> float:
    """Formation heading for a straight offset crossing that needs the least turn from
    ``current``: among 360 sampled headings, those for which the obstacle's path (offset
    ``offset`` from the object's path, world frame) keeps ``clearance`` from every robot."""
    phi, lo, hi = _offset_crossings(f, clearance, directions=360)
    e = float(np.dot(offset, [-np.sin(direction), np.cos(direction)]))
    ok = (lo <= e) & (e <= hi)
    if not ok.any():
        return fallback
    psi = direction - phi[ok]
    return float(psi[np.argmin(np.abs(np.angle(np.exp(1j * (psi - current)))))])


def motion_from_legs(scenario: Scenario, formation: Formation | Route,
                     legs: tuple[Leg, ...] | None = None) -> Motion:
    """Time-stamped samples of the team along a route (Algorithm 2 on crossing legs,
    formation changes in place on reform legs), starting at heading 0 at
    ``scenario.start``.

    Parameters
    ----------
    scenario : Scenario
    formation : Formation or Route
        A route (its formations and legs), or one formation with ``legs``.
    legs : tuple of Leg, optional

    Returns
    -------
    Motion
    """
    require_instance(scenario, Scenario, "scenario")
    require_instance(formation, (Formation, Route), "formation")
    if legs is not None:
        legs = require_instances(legs, Leg, "legs")
    if isinstance(formation, Route):
        return _motion_from_legs(scenario, formation.formations, formation.legs,
                                 formation.first)
    return _motion_from_legs(scenario, (formation,), legs or (), 0)


def _motion_from_legs(scenario: Scenario, forms: tuple[Formation, ...],
                      legs: tuple[Leg, ...], first: int) -> Motion:
    """:func:`motion_from_legs` on validated inputs: the formations ``forms`` legs refer
    to, starting in ``forms[first]``."""
    team = scenario.team
    b = _Builder(forms[first], team.speed, team.rotation_speed, scenario.start)
    records = []
    for leg in legs:
        if leg.kind == "reform":
            b.reform(forms[leg.formation])
            continue
        if leg.kind != "cross":
            b.translate(leg.end)
            continue
        f = b.f
        o = scenario.world.obstacle(str(leg.obstacle))
        u = leg.end - leg.start
        du = float(np.arctan2(u[1], u[0]))
        if leg.heading is not None:                         # straight offset crossing
            closest = leg.start + u * float(np.dot(o.mec_center - leg.start, u) / np.dot(u, u))
            heading = _straight_heading(f, o.mec_radius + team.clearance, du,
                                        o.mec_center - closest, b.h[-1], leg.heading)
            t0 = b.t[-1]
            b.rotate(_wrap(heading - b.h[-1]))
            t1 = b.t[-1]
            b.translate(closest)
            t2 = b.t[-1]
            b.translate(leg.end)
            ang = _wrap(du - b.h[-1])
            records.append(CrossingRecord(o.id, np.array([t0, t1, t2, t2, b.t[-1]]), du, ang,
                                          _wrap(ang + np.pi), 0.0, "straight"))
            continue
        pairs = _crossing_pairs(f, o.mec_radius + team.clearance)
        best = abs(pairs[0][2])
        cands = [p for p in pairs if abs(abs(p[2]) - best) <= _tol.TURN_TIE]
        h = b.h[-1]
        a_in, a_out, turn = min(cands, key=lambda p: abs(_wrap(du - p[0] - h)))
        t0 = b.t[-1]
        b.rotate(_wrap(du - a_in - h))                      # step 1
        t1 = b.t[-1]
        b.translate(o.mec_center)                           # step 2
        t2 = b.t[-1]
        b.rotate(turn)                                      # step 3
        t3 = b.t[-1]
        b.translate(leg.end)                                # step 4
        records.append(CrossingRecord(o.id, np.array([t0, t1, t2, t3, b.t[-1]]), du, a_in,
                                      a_out, turn))
    times = np.asarray(b.t)
    center = np.asarray(b.c)
    robots = np.asarray(b.robots)
    obj = np.column_stack([center, np.asarray(b.z)])
    if np.isnan(obj[:, 2]).any():
        obj[np.isnan(obj[:, 2]), :2] = np.nan
        _fill_reforms(scenario, robots, obj)
    return Motion(times, center, np.asarray(b.h), robots, obj, tuple(records))
