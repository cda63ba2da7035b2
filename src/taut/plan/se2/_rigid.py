"""The footprint-agnostic core of the SE(2) lattice search: one search, two users.

The sheet planner (:mod:`taut.plan.se2._lattice`, every formation a layer) and the
navigation of a mobile cable robot's coupled bases (:mod:`taut.cdpr.mission.navigation`, one
rigid footprint) share the lattice (:func:`lattice_grid`), the links to an exact goal
(:func:`goal_links`), the compiled A* (:func:`taut.plan._kernels.lattice.lattice_astar`,
every move proved by conservative advancement) and the merging and shortening of the path
found (:func:`merge_straight`). :func:`rigid_route` is the one-body search built from them.

A heading lattice starts at ``-pi`` (the kernel's convention). :func:`rigid_route` keeps
the start's exact heading on the lattice by turning the body's points instead: with
``c = -pi - yaw_start``, the body turned by ``-c`` at lattice heading ``psi`` is the body
at heading ``psi - c``, so the search runs on lattice headings and the route is turned back.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from .. import _tol
from .._kernels.clearance import motion_clear
from .._kernels.lattice import OFFSETS, lattice_astar
from ..world import World
from ._body import BodyChecker, kernel_world
from ._rrt import shortcut

__all__ = ["Grid", "lattice_grid", "goal_links", "merge_straight", "RigidRoute",
           "rigid_route", "MAX_NODES"]

#: Most lattice nodes (every layer together); a larger problem gets a coarser spacing
#: (reported in the result) so that memory (about 17 bytes a node) stays bounded.
MAX_NODES = 8_000_000


@dataclass(frozen=True, eq=False)
class Grid:
    """Lattice cells in the free space, aligned on the start."""

    cells: np.ndarray        # (C, 2) positions in the free space
    nbr: np.ndarray          # (C, 8) neighbour cells in OFFSETS order, -1 for none
    spacing: float
    nk: int
    start_cell: int

    @property
    def dpsi(self) -> float:
        return 2 * np.pi / self.nk


def lattice_grid(geometry: shapely.Polygon, free_space: np.ndarray, start: np.ndarray,
                 spacing: float, radius: float, layers: int) -> Grid:
    """Lattice cells inside ``geometry`` (vertices ``free_space``), aligned on ``start``
    (2,), with headings such that a heading step moves a point ``radius`` from the
    reference about a spacing; coarser than ``spacing`` when the problem would exceed
    ``MAX_NODES``."""
    lo, hi = free_space.min(axis=0), free_space.max(axis=0)
    h = float(spacing)
    while True:
        nk = int(max(16, 8 * np.ceil(2 * np.pi * radius / h / 8)))
        below = np.floor((start - lo) / h).astype(int)
        origin = start - below * h
        n = np.floor((hi - origin) / h).astype(int) + 1
        if float(n[0]) * float(n[1]) * nk * layers > 4 * MAX_NODES:   # cheap bound first
            h *= 1.25
            continue
        i, j = np.meshgrid(np.arange(n[0]), np.arange(n[1]), indexing="ij")
        x, y = origin[0] + i.ravel() * h, origin[1] + j.ravel() * h
        inside = shapely.contains_xy(geometry, x, y)
        if inside.sum() * nk * layers <= MAX_NODES:
            break
        h *= 1.25
    index = np.full(n[0] * n[1], -1, dtype=np.int64)
    index[inside] = np.arange(inside.sum())
    ci, cj = i.ravel()[inside], j.ravel()[inside]
    nbr = np.full((len(ci), 8), -1, dtype=np.int64)
    for m, (di, dj) in enumerate(OFFSETS):
        ii, jj = ci + di, cj + dj
        ok = (ii >= 0) & (ii < n[0]) & (jj >= 0) & (jj < n[1])
        nbr[ok, m] = index[ii[ok] * n[1] + jj[ok]]
    return Grid(np.column_stack([x[inside], y[inside]]), nbr, h, nk,
                int(index[below[0] * n[1] + below[1]]))


def goal_links(grid: Grid, checkers: list[BodyChecker], goal: np.ndarray, speed: float,
               rotation_speed: float, heading: float | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Node ids joined to the exact goal ``goal`` (2,) and the time of that last straight
    move, s. With ``heading`` None the goal's heading is free: every lattice heading at
    which the goal pose is valid, reached from the four cells around it at that heading.
    With a ``heading`` (rad, lattice frame) the goal pose has it, reached from the four
    cells at the two lattice headings around it. Every link is proved (the goal pose
    valid, the straight motion valid by conservative advancement)."""
    d = np.linalg.norm(grid.cells - goal, axis=1)
    near = np.flatnonzero(d <= grid.spacing * np.sqrt(2) + _tol.GEOMETRY_TOL)
    C, links = len(grid.cells), {}
    if heading is None:
        ks = list(range(grid.nk))
    else:
        k0 = int(np.floor((heading + np.pi) / grid.dpsi))
        ks = [k0 % grid.nk, (k0 + 1) % grid.nk]
    for L, c in enumerate(checkers):
        for k in ks:
            psi = -np.pi + k * grid.dpsi
            g = np.array([*goal, psi if heading is None else heading])
            turn = 0.0 if heading is None else abs(float(np.angle(np.exp(1j * (g[2] - psi)))))
            g[2] = psi + (0.0 if heading is None else float(np.angle(np.exp(1j * (g[2] - psi)))))
            if not c.valid(g[None])[0]:
                continue
            for cell in near:
                p = np.array([*grid.cells[cell], psi])
                if c.valid(p[None])[0] and motion_clear(
                        c._local, c.radius, c._walls, c._obst, c._verts, c.clearance_rule, p,
                        g, _tol.MOTION_MARGIN, _tol.MIN_ADVANCE) > 0:
                    t = d[cell] / speed
                    if heading is not None:
                        t = max(t, turn / rotation_speed)
                    links[(L * C + int(cell)) * grid.nk + k] = t
    ids = np.array(sorted(links), dtype=np.int64)
    return ids, np.array([links[i] for i in ids])


def merge_straight(checker: BodyChecker, run: list[np.ndarray], rng: np.random.Generator
                   ) -> np.ndarray:
    """Waypoints (K, 3) through the lattice poses ``run`` (headings unwrapped), runs of
    equal lattice moves merged into one straight motion while they turn by at most pi/2 in
    all (the shortcut needs edges that turn by less than pi), then shortcut."""
    w = np.array(run)
    w[:, 2] = np.unwrap(w[:, 2])
    if len(w) > 2:
        keep = [0]
        for k in range(1, len(w) - 1):
            bend = np.abs((w[k + 1] - w[k]) - (w[k] - w[k - 1])).max() > _tol.GEOMETRY_TOL
            if bend or abs(w[k + 1, 2] - w[keep[-1], 2]) > np.pi / 2:
                keep.append(k)
        w = shortcut(checker, w[keep + [len(w) - 1]], rng)
    return w


@dataclass(frozen=True, eq=False)
class RigidRoute:
    """Outcome of :func:`rigid_route`.

    Attributes
    ----------
    waypoints : ndarray (K, 3) or None
        Straight SE(2) segments from the start to the goal (headings unwrapped, the
        body's true headings), proved valid; None when not found.
    spacing : float
        Lattice spacing used, m.
    headings : int
    expanded : int
        Nodes A* expanded.
    exhausted : bool
        The expansion budget ran out (otherwise, without waypoints, the lattice holds no
        route at all).
    start_valid, goal_valid : bool
        Whether the end poses keep the rules (with ``STATE_CLEARANCE`` to spare).
    goal_linked : bool
        Whether the goal is joined to the lattice (a valid goal may still be too tight
        to reach from the lattice cells around it).
    cost : float
        Duration of the lattice path, s (inf when none).
    """

    waypoints: np.ndarray | None
    spacing: float
    headings: int
    expanded: int
    exhausted: bool
    start_valid: bool
    goal_valid: bool
    goal_linked: bool
    cost: float = np.inf


def _turned(local: np.ndarray, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return local @ np.array([[c, -s], [s, c]]).T


def rigid_route(local: np.ndarray, world: World, clearance_rule: float, start: np.ndarray,
                goal: np.ndarray, *, spacing: float, speed: float, rotation_speed: float,
                expansions: int, rng: np.random.Generator, margin: float = 0.0
                ) -> RigidRoute:
    """Fastest lattice route of a rigid body (points ``local`` (N, 2), m, their hull the
    body) from pose ``start`` to pose ``goal`` (3,) in ``world`` (every obstacle blocked,
    the hull keeping ``margin`` from it; every point ``clearance_rule`` from walls and
    obstacles), moves costing ``max(distance / speed, turn / rotation_speed)`` s, then
    merged and shortcut (module docstring).
    """
    offset = -np.pi - float(start[2])
    walls, obst, verts = kernel_world(world, [True] * len(world.obstacles), margin)
    checker = BodyChecker(_turned(np.asarray(local, float), -offset), walls, obst, verts,
                          clearance_rule)
    s0 = np.array([start[0], start[1], -np.pi])
    gpsi = float(np.angle(np.exp(1j * (goal[2] + offset))))
    g0 = np.array([goal[0], goal[1], gpsi])
    grid = lattice_grid(world.geometry, world.free_space, s0[:2], spacing, checker.radius, 1)
    start_ok, goal_ok = bool(checker.valid(s0[None])[0]), bool(checker.valid(g0[None])[0])
    goals, goal_cost = goal_links(grid, [checker], g0[:2], speed, rotation_speed, gpsi)
    C, nk = len(grid.cells), grid.nk
    if not (start_ok and goal_ok and len(goals)):
        return RigidRoute(None, grid.spacing, nk, 0, False, start_ok, goal_ok, len(goals) > 0)
    motion = np.array([speed, rotation_speed, _tol.MOTION_MARGIN, _tol.MIN_ADVANCE,
                       _tol.STATE_CLEARANCE])
    path, best, expanded = lattice_astar(
        grid.cells, grid.nbr, nk, np.array([grid.spacing, grid.dpsi]), checker._local[None],
        np.array([checker.radius]), walls, obst[None], verts, checker.clearance_rule, motion,
        np.full((1, 1), np.inf), obst[None, None], np.array([grid.start_cell * nk],
                                                               dtype=np.int64),
        goals, goal_cost, g0[:2].copy(), int(expansions), np.ones(1))
    exhausted = bool(expanded > expansions)
    if not len(path):
        return RigidRoute(None, grid.spacing, nk, int(expanded), exhausted, True, True, True)
    run = [np.array([*grid.cells[(n // nk) % C], -np.pi + (n % nk) * grid.dpsi])
           for n in path]
    last = run[-1][2] + float(np.angle(np.exp(1j * (gpsi - run[-1][2]))))
    run.append(np.array([*g0[:2], last]))
    w = merge_straight(checker, run, rng)
    w[:, 2] -= offset
    return RigidRoute(w, grid.spacing, nk, int(expanded), exhausted, True, True, True,
                      float(best))
