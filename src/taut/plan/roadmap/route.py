"""Global route of the formation (planning paper Sec. IV, Fig. 4), on shapely geometry and a
SciPy graph search.

The formation is rigid along a route and is represented by the disc of radius
``formation.reach`` about the object's projection (every robot footprint plus the lateral
safety lies in it, whatever the heading; cf. eq. 1). Its configuration space is the free
space eroded by that radius minus every obstacle grown by it. Routes are shortest paths in
the visibility graph of that region (exact: vertices of a slightly smaller region, edges
checked with ``shapely.covers`` on the true one), searched with
:func:`scipy.sparse.csgraph.dijkstra`.

Crossing (when allowed): an obstacle the formation can cross (eqs. 2-4 and a way through,
:func:`crossable`) may lie on the route. *Crossing edges* are straight segments over it:
for each of ``DIRECTIONS`` headings, (a) the paper's Algorithm 2 through the obstacle's
centre, from where the disc just clears it to the symmetric point beyond, costing both
translations plus the turn at the obstacle; (b) with ``straight_crossings``, ``OFFSETS``
parallel segments at lateral offsets where some formation heading lets the obstacle pass
between two robots (:func:`~taut.plan.formations.optimal.offset_crossings`), costing the
translation only. The disc swept along an edge must clear the walls and every other
obstacle. Obstacles not crossed are bypassed. With several formations the roadmap has a
layer per formation joined by in-place formation changes.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import shapely
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra
from shapely.geometry import Point
from shapely.geometry.polygon import orient
from shapely.ops import unary_union

from ..._outcome import check_status
from .. import _tol
from ..formations.optimal import Formation, _crossing_pairs, _offset_crossings
from ..world import Obstacle, Scenario
from ..._validate import as_flag, require_instance, require_instances
from ..._repr import CompactRepr

__all__ = ["Leg", "Route", "find_route"]

#: Number of crossing headings tried per crossable obstacle.
DIRECTIONS = 24
#: Lateral offsets tried per heading for straight offset crossings.
OFFSETS = 21
#: Buffer resolution (segments per quarter circle) of the configuration space.
QUAD_SEGS = 8
_EPS = _tol.CROSSING_OVERSHOOT


@dataclass(frozen=True, eq=False, repr=False)
class Leg(CompactRepr):
    """One piece of a route: a straight ``"move"``, a ``"cross"``-ing of ``obstacle``
    (Algorithm 2) from ``start`` through the obstacle's centre to ``end``, or a
    ``"reform"`` into formation number ``formation`` in place. ``formation`` indexes
    :attr:`Route.formations` (the formation used on, or after, the leg). A crossing with
    ``heading`` set is a straight offset crossing made at that formation heading (rad,
    world frame; :func:`~taut.plan.formations.optimal.offset_crossings`)."""

    kind: str
    start: np.ndarray
    end: np.ndarray
    obstacle: str | None = None
    formation: int = 0
    heading: float | None = None

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.end - self.start))


@dataclass(frozen=True, eq=False)
class Route:
    """Result of :func:`find_route`.

    Attributes
    ----------
    success : bool
    status : {"ok", "no_route"}
    message : str
        Why no route exists, or a summary.
    legs : tuple of Leg
    cost : float
        Graph cost, s (translation time plus the turns at crossed obstacles and the
        formation changes).
    formations : tuple of Formation
        The formations legs refer to.
    first : int
        Index of the formation at the start.
    """

    success: bool
    status: str
    message: str
    legs: tuple[Leg, ...] = ()
    cost: float = float("inf")
    formations: tuple[Formation, ...] = ()
    first: int = 0

    def __post_init__(self) -> None:
        check_status(self.status)

    @property
    def crossed(self) -> tuple[str, ...]:
        return tuple(str(leg.obstacle) for leg in self.legs if leg.kind == "cross")


def crossable(scenario: Scenario, formation: Formation, obstacle: Obstacle, *,
              straight: bool = True) -> str | None:
    """None when ``formation`` can cross ``obstacle`` (15b, and a usable side pair of
    Algorithm 2 or, with ``straight``, a straight offset crossing), else the reason it
    cannot."""
    team = scenario.team
    if obstacle.height > formation.max_height + _tol.ANGLE_TOL:
        return (f"obstacle {obstacle.id!r} is {obstacle.height:.3g} m tall, the formation "
                f"clears at most {formation.max_height:.3g} m")
    if obstacle.diameter > formation.max_diameter + _tol.ANGLE_TOL:
        return (f"obstacle {obstacle.id!r} is {obstacle.diameter:.3g} m wide, at most "
                f"{max(formation.max_diameter, 0):.3g} m fits between the robots")
    c = obstacle.mec_radius + team.clearance
    if not _crossing_pairs(formation, c) and not (straight
                                                  and len(_offset_crossings(formation, c)[0])):
        return f"no side of the formation lets obstacle {obstacle.id!r} pass under the sheet"
    return None


def _inflate(radius: float) -> float:
    return radius / np.cos(np.pi / (4 * QUAD_SEGS))


def _region(scenario: Scenario, radius: float, skip: str | None = None):
    """Free space eroded by ``radius`` minus obstacles grown by it. Buffers approximate
    arcs by chords, so the radius is enlarged by 1/cos(pi/(4 QUAD_SEGS)): every chord then
    lies outside the exact arc and the region is conservative."""
    world = scenario.world
    radius = _inflate(radius)
    base = world.geometry.buffer(-radius, quad_segs=QUAD_SEGS)
    grown = [o.geometry.buffer(radius, quad_segs=QUAD_SEGS) for o in world.obstacles
             if o.id != skip]
    if grown:
        base = base.difference(unary_union(grown))
    return base


def _vertices(region) -> np.ndarray:
    """Reflex vertices of the region (where it turns away from the free side): the only
    ring vertices a shortest path can bend at."""
    pts = []
    for poly in getattr(region, "geoms", [region]):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        poly = orient(poly, 1.0)                  # free side on the left of every ring
        for ring in [poly.exterior, *poly.interiors]:
            p = np.asarray(ring.coords)[:-1]
            a, b = p - np.roll(p, 1, axis=0), np.roll(p, -1, axis=0) - p
            turn = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
            pts.append(p[turn < 0])
    return np.concatenate(pts) if pts else np.zeros((0, 2))


class _Layer:
    """One formation's share of the roadmap: region, own points, crossing edges."""

    def __init__(self, scenario: Scenario, formation: Formation, allow_crossing: bool,
                 straight: bool):
        team = scenario.team
        self.formation = formation
        R = formation.reach
        self.region = _region(scenario, R)
        shapely.prepare(self.region)
        own = [scenario.start, scenario.goal]
        own.extend(_vertices(_region(scenario, R + _tol.VERTEX_INSET * max(R, 1.0))))
        # (local in, local out, cost s, obstacle id, world heading of the formation for a
        # straight offset crossing or None for Algorithm 2)
        self.cross: list[tuple[int, int, float, str, float | None]] = []
        self.reasons: list[str] = []
        if allow_crossing and not self.region.is_empty:
            for o in scenario.world.obstacles:
                why = crossable(scenario, formation, o, straight=straight)
                if why is not None:
                    self.reasons.append(why)
                    continue
                corridor = _region(scenario, R, skip=o.id)
                shapely.prepare(corridor)
                for p_in, p_out, cost, phi in self._crossing_edges(scenario, formation, o,
                                                                   straight):
                    segs = shapely.linestrings(np.stack([p_in, p_out], axis=1))
                    ok = (shapely.covers(corridor, segs)
                          & shapely.covers(self.region, shapely.points(p_in))
                          & shapely.covers(self.region, shapely.points(p_out)))
                    for k in np.flatnonzero(ok):
                        i = len(own)
                        own.extend([p_in[k], p_out[k]])
                        self.cross.append((i, i + 1, float(cost[k]), o.id,
                                           None if phi is None else float(phi[k])))
        self.own = np.asarray(own, dtype=float)
        self.points = self.own

    @staticmethod
    def _crossing_edges(scenario: Scenario, formation: Formation, o: Obstacle,
                        straight: bool):
        """Candidate crossing segments of obstacle ``o``: Algorithm 2 through its centre
        (``DIRECTIONS`` headings), and straight offset crossings (``OFFSETS`` lateral
        positions per heading, at the best formation heading for each)."""
        team = scenario.team
        v, omega = team.speed, team.rotation_speed
        R = _inflate(formation.reach)
        c = o.mec_radius + team.clearance
        a = 2 * np.pi * np.arange(DIRECTIONS) / DIRECTIONS
        u = np.column_stack([np.cos(a), np.sin(a)])
        pairs = _crossing_pairs(formation, c)
        if pairs:
            L = R + o.mec_radius + _EPS * max(R, 1.0)
            yield (o.mec_center - L * u, o.mec_center + L * u,
                   np.full(DIRECTIONS, 2 * L / v + abs(pairs[0][2]) / omega), None)
        if not straight:
            return
        phi, lo, hi = _offset_crossings(formation, c)
        if not len(phi):
            return
        extent = float(np.linalg.norm(formation.robots, axis=1).max())
        for e in np.linspace(-extent, extent, OFFSETS):
            inside = (lo <= e) & (e <= hi)
            if not inside.any():
                continue
            # Heading with the most room around this offset.
            room = np.where(inside, np.minimum(e - lo, hi - e), -np.inf)
            j = int(np.argmax(room))
            # Object path: offset by -e from the obstacle's centre (left normal of u).
            nrm = np.column_stack([-u[:, 1], u[:, 0]])
            half = np.sqrt(max((R + o.mec_radius) ** 2 - e * e, 0.0)) + _EPS * max(R, 1.0)
            mid = o.mec_center - e * nrm
            yield (mid - half * u, mid + half * u, np.full(DIRECTIONS, 2 * half / v),
                   a - phi[j])

    def add_shared(self, others: list[np.ndarray]) -> None:
        """Also hold the other layers' points that lie in this region (where the team can
        switch formation)."""
        if self.region.is_empty or not others:
            return
        extra = np.concatenate(others)
        inside = shapely.covers(self.region, shapely.points(extra))
        self.points = np.concatenate([self.own, extra[inside]])

    def edges(self, speed: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        P = self.points
        iu, ju = np.triu_indices(len(P), 1)
        if self.region.is_empty or not len(iu):
            return np.zeros(0, int), np.zeros(0, int), np.zeros(0)
        vis = shapely.covers(self.region,
                             shapely.linestrings(np.stack([P[iu], P[ju]], axis=1)))
        iu, ju = iu[vis], ju[vis]
        w = np.linalg.norm(P[iu] - P[ju], axis=1) / speed
        rows, cols, wts = [iu, ju], [ju, iu], [w, w]
        if self.cross:
            ce = np.array([(a, b) for a, b, *_ in self.cross], dtype=int)
            cw = np.array([c for _, _, c, *_ in self.cross])
            rows += [ce[:, 0], ce[:, 1]]
            cols += [ce[:, 1], ce[:, 0]]
            wts += [cw, cw]
        return np.concatenate(rows), np.concatenate(cols), np.concatenate(wts)


def reform_time(a: Formation, b: Formation, speed: float) -> float:
    """Time to change formation ``a`` into ``b`` in place (robots move straight at the
    team's speed, object projection and heading kept), s."""
    return float(np.linalg.norm(b.robots - a.robots, axis=1).max()) / speed


def _no_route(message: str) -> Route:
    return Route(False, "no_route", message)


def _ends_message(layers: list[_Layer], scenario: Scenario, R: float) -> str | None:
    """Why start or goal has no room for any formation (None when both have)."""
    if all(L.region.is_empty for L in layers):
        return f"the formation (reach {R:.3g} m) does not fit anywhere in the free space"
    for name, p in (("start", scenario.start), ("goal", scenario.goal)):
        if not any(L.region.covers(Point(p)) for L in layers):
            return f"no room for the formation (reach {R:.3g} m) at the {name}"
    return None


def _graph(layers: list[_Layer], forms: list[Formation], speed: float):
    """Sparse graph of every layer, the virtual source/sink and the formation changes;
    returns (csr graph, layer offsets, source, sink)."""
    offsets = np.cumsum([0] + [len(L.points) for L in layers])
    n = int(offsets[-1]) + 2                        # + virtual source and sink
    src, sink = n - 2, n - 1
    rows, cols, wts = [], [], []
    for k, L in enumerate(layers):
        r, c, w = L.edges(speed)
        rows.append(r + offsets[k])
        cols.append(c + offsets[k])
        wts.append(w)
        if L.region.is_empty:
            continue
        for local, end in ((0, "start"), (1, "goal")):
            if L.region.covers(Point(L.points[local])):
                rows.append(np.array([src if end == "start" else offsets[k] + local]))
                cols.append(np.array([offsets[k] + local if end == "start" else sink]))
                wts.append(np.zeros(1))
    for k in range(len(layers)):
        for j in range(len(layers)):
            if j == k or layers[k].region.is_empty or layers[j].region.is_empty:
                continue
            A, B = layers[k].points, layers[j].points
            # Same point in both layers: a formation change there.
            d = np.linalg.norm(A[:, None, :] - B[None, :, :], axis=2)
            ia, ib = np.nonzero(d <= _tol.SAME_POINT)
            rows.append(ia + offsets[k])
            cols.append(ib + offsets[j])
            wts.append(np.full(len(ia), reform_time(forms[k], forms[j], speed)))
    rows_a, cols_a = np.concatenate(rows).astype(int), np.concatenate(cols).astype(int)
    wts_a = np.maximum(np.concatenate(wts), _tol.MIN_EDGE_COST)
    graph = coo_matrix((wts_a, (rows_a, cols_a)), shape=(n, n)).tocsr()
    return graph, offsets, src, sink


def _legs(path: list[int], layers: list[_Layer], offsets: np.ndarray
          ) -> tuple[tuple[Leg, ...], int]:
    """Legs of a graph path (global node indices, source and sink removed) and the index
    of the first formation."""
    n = int(offsets[-1])
    layer_of = np.searchsorted(offsets, np.arange(n), side="right") - 1

    def where(g: int) -> tuple[int, int]:
        k = int(layer_of[g])
        return k, g - int(offsets[k])

    crossing = {}
    for k, L in enumerate(layers):
        for a, b, _, oid, phi in L.cross:
            crossing[(offsets[k] + a, offsets[k] + b)] = (oid, phi)
            crossing[(offsets[k] + b, offsets[k] + a)] = (oid, phi)
    legs = []
    for a, b in zip(path[:-1], path[1:]):
        (ka, ia), (kb, ib) = where(a), where(b)
        pa, pb = layers[ka].points[ia].copy(), layers[kb].points[ib].copy()
        if ka != kb:
            legs.append(Leg("reform", pa, pb, None, kb))
            continue
        oid, phi = crossing.get((a, b), (None, None))  # type: ignore[assignment]
        legs.append(Leg("cross" if oid is not None else "move", pa, pb, oid, ka, phi))
    return tuple(legs), where(path[0])[0]


def find_route(scenario: Scenario, formation: Formation | Sequence[Formation], *,
               allow_crossing: bool = True, straight_crossings: bool = True) -> Route:
    """Shortest-time route of the object's projection from start to goal on the disc-model
    roadmap (module docstring).

    Parameters
    ----------
    scenario : Scenario
    formation : Formation or sequence of Formation
        The formation(s) the team may use. With several, the roadmap has one layer per
        formation and the team may change formation in place wherever both fit (a
        ``"reform"`` leg, costed by :func:`reform_time`); it may start and end in any.
    allow_crossing : bool
        False gives the disc-model bypass baseline.
    straight_crossings : bool
        Also allow straight offset crossings (False: the paper's Algorithm 2 only).

    Returns
    -------
    Route
        ``success`` False (status ``no_route``) with a message when the start or goal has
        no room for the formation or no route connects them.
    """
    require_instance(scenario, Scenario, "scenario")
    if isinstance(formation, (list, tuple)):
        forms = list(require_instances(formation, Formation, "formation", min_count=1))
    else:
        forms = [require_instance(formation, Formation, "formation")]
    return _find_route(scenario, forms,
                       allow_crossing=as_flag(allow_crossing, "allow_crossing"),
                       straight_crossings=as_flag(straight_crossings, "straight_crossings"))


def _find_route(scenario: Scenario, forms: list[Formation], *, allow_crossing: bool,
                straight_crossings: bool) -> Route:
    """:func:`find_route` on validated inputs (one formation or more, in a list)."""
    team = scenario.team
    layers = [_Layer(scenario, f, allow_crossing, straight_crossings) for f in forms]
    why = _ends_message(layers, scenario, min(f.reach for f in forms))
    if why is not None:
        return _no_route(why)
    if len(layers) > 1:
        for k, L in enumerate(layers):
            L.add_shared([M.own for j, M in enumerate(layers) if j != k])
    graph, offsets, src, sink = _graph(layers, forms, team.speed)
    dist, pred = dijkstra(graph, directed=True, indices=src, return_predecessors=True)
    if not np.isfinite(dist[sink]):
        why = "no route: the formation cannot pass between the obstacles and walls"
        reasons = list(dict.fromkeys(r for L in layers for r in L.reasons))
        if reasons:
            why += " and cannot cross (" + "; ".join(reasons) + ")"
        return _no_route(why)
    path = [int(pred[sink])]
    while path[-1] != src:
        path.append(int(pred[path[-1]]))
    legs, first = _legs(path[::-1][1:], layers, offsets)
    return Route(True, "ok", f"route of {len(legs)} legs, {float(dist[sink]):.2f} s", legs,
                 float(dist[sink]), tuple(forms), first)
