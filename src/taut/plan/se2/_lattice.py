"""Multi-formation lattice search in SE(2) (issue 14's complete search; our construction).

Every formation of the library is a layer: a lattice of poses ``(x, y, psi)`` with
``spacing`` metres between positions (the lattice is aligned on the start) and headings
``dpsi`` apart, chosen so that a heading step moves the farthest robot at most about one
spacing. A* (:mod:`taut.plan._kernels.lattice`) searches the layers together: rigid moves
to the 26 lattice neighbours where the straight motion is *proved* valid, and in-place
formation changes where they are valid for the geometry (every robot moving straight,
obstacles under the hull low enough for the lowest object on the way) and for the
quasi-static model (:func:`~taut.plan.se2._motion.change_profile`: no jump, the change ends
in the new formation's rest state; the model is invariant under planar rigid motions, so
one simulation per ordered pair of formations decides it everywhere). A change on the path
found must also keep the object under the robots' position error
(:func:`~taut.plan.checks.robustness.change_tolerates`); one that does not is refused everywhere
and the search runs again. Moves cost their
duration, so the path found is the fastest lattice path, with any number of formation
changes; time spent in a squeezed formation counts ``SQUEEZED_WEIGHT`` times (the
all-taut formations of the paper share the load between every robot, so they are
preferred wherever they fit).

The search is *resolution-complete*: when the lattice holds no path, no path exists whose
every pose keeps the rules with about a spacing of robot motion to spare (such a path has
lattice poses near it, joined by proved moves); tighter passages need a finer spacing or
the sampling search. The path is then shortened rigid piece by rigid piece
(:func:`~taut.plan.se2._rrt.shortcut`, seeded), and returned as pieces for sampling and
verification.

The lattice, the goal links and the merging of the path are the footprint-agnostic core
of :mod:`taut.plan.se2._rigid`, shared with the navigation of a mobile cable robot's
coupled bases (:mod:`taut.cdpr.mission.navigation`): one search, two users.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _tol
from .._kernels.lattice import lattice_astar
from ._motion import Piece, change_profile
from ._rigid import MAX_NODES, goal_links, lattice_grid, merge_straight
from ._space import PoseChecker
from ..checks.robustness import change_tolerates
from ..formations.optimal import Formation
from ..world import Scenario

__all__ = ["LatticeResult", "lattice_search", "MAX_NODES"]

@dataclass(frozen=True, eq=False)
class LatticeResult:
    """Outcome of :func:`lattice_search`.

    Attributes
    ----------
    pieces : list of Piece or None
        The plan's rigid pieces and formation changes (None: no lattice path found).
    spacing : float
        Lattice spacing used, m.
    headings : int
        Headings per position.
    expanded : int
        Nodes expanded by A*.
    exhausted : bool
        The expansion budget ran out (otherwise, when ``pieces`` is None, the lattice
        holds no path at all).
    refused_changes : tuple of str
        Formation changes the quasi-static model refuses, and why.
    cost : float
        Duration of the lattice path, s, before shortening (inf when none).
    """

    pieces: list[Piece] | None
    spacing: float
    headings: int
    expanded: int
    exhausted: bool
    refused_changes: tuple[str, ...]
    cost: float = np.inf


def _changes(scenario: Scenario, forms: list[Formation], checkers: list[PoseChecker]
             ) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Cost (L, L) of every allowed change (inf: refused by the quasi-static model) and
    its obstacle rows: an obstacle may be under the hull during a change only when the
    lowest object on the way clears it by the height safety plus ``MAX_OBJECT_STEP`` (the
    verifier samples a change until the object moves at most that much between samples,
    and allows for it between them), and crossing is allowed."""
    L = len(forms)
    cost = np.full((L, L), np.inf)
    obst = np.stack([np.stack([c._obst for c in checkers])] * L)
    refused = []
    safety = scenario.team.height_safety
    for a in range(L):
        for b in range(L):
            if a == b:
                continue
            prof = change_profile(scenario, forms[a], forms[b])
            if prof.message is not None:
                refused.append(f"{forms[a].kind} (object at {forms[a].object_height:.3g} m) "
                               f"to {forms[b].kind} ({forms[b].object_height:.3g} m): "
                               f"{prof.message}")
                continue
            cost[a, b] = max(prof.duration, _tol.MIN_EDGE_COST)
            if len(obst[a, b]):
                low = prof.lowest - _tol.MAX_OBJECT_STEP
                tall = np.array([o.height > low - safety + _tol.GEOMETRY_TOL
                                 for o in scenario.world.obstacles])
                obst[a, b][:, 3] = (tall | (not checkers[a].allow_crossing)).astype(float)
    return cost, obst, refused


def lattice_search(scenario: Scenario, formations: list[Formation],
                   checkers: list[PoseChecker], *, spacing: float, expansions: int,
                   rng: np.random.Generator) -> LatticeResult:
    """Fastest lattice path over every formation of ``formations`` (module docstring).

    Parameters
    ----------
    scenario : Scenario
    formations : list of Formation
    checkers : list of PoseChecker
        One per formation, all with the same crossing rule.
    spacing : float
        Lattice spacing, m.
    expansions : int
        Most nodes A* expands (the deterministic budget).
    rng : numpy.random.Generator
        Seeds the shortening of the path.
    """
    team = scenario.team
    radius = max(c.radius for c in checkers)
    world = scenario.world
    grid = lattice_grid(world.geometry, world.free_space, scenario.start, spacing, radius,
                        len(formations))
    cost, change_obst, refused = _changes(scenario, formations, checkers)
    goals, goal_cost = goal_links(grid, list(checkers), scenario.goal, team.speed,
                                  team.rotation_speed)
    C, nk = len(grid.cells), grid.nk
    starts = np.array([(L * C + grid.start_cell) * nk + k for L in range(len(checkers))
                       for k in range(nk)], dtype=np.int64)
    starts = starts[[c.valid(np.array([[*scenario.start, -np.pi + k * grid.dpsi]]))[0]
                     for c in checkers for k in range(nk)]]
    motion = np.array([team.speed, team.rotation_speed, _tol.MOTION_MARGIN,
                       _tol.MIN_ADVANCE, _tol.STATE_CLEARANCE])
    weight = np.array([_tol.SQUEEZED_WEIGHT if f.kind == "squeezed" else 1.0
                       for f in formations])
    total = 0
    while True:
        path, best, expanded = lattice_astar(
            grid.cells, grid.nbr, nk, np.array([grid.spacing, grid.dpsi]),
            np.stack([c._local for c in checkers]), np.array([c.radius for c in checkers]),
            checkers[0]._walls, np.stack([c._obst for c in checkers]), checkers[0]._verts,
            checkers[0].clearance_rule, motion, cost, change_obst, starts, goals, goal_cost,
            np.asarray(scenario.goal, dtype=float), int(expansions), weight)
        total += int(expanded)
        layers = [int(n // (nk * C)) for n in path]
        used = [(a, b) for a, b in zip(layers[:-1], layers[1:]) if a != b]
        if all(change_tolerates(scenario, formations[a], formations[b]) is None
               for a, b in used):
            break
        # A change of the path drops the object: check every allowed change now (so A*
        # runs at most twice), refuse the fragile ones everywhere, and search again.
        for a, b in zip(*np.nonzero(np.isfinite(cost))):
            why = change_tolerates(scenario, formations[a], formations[b])
            if why is not None:
                cost[a, b] = np.inf
                refused.append(why)
    pieces = None
    if len(path):
        poses = [(int(n // (nk * C)), np.array([*grid.cells[(n // nk) % C],
                                                -np.pi + (n % nk) * grid.dpsi]))
                 for n in path]
        poses.append((poses[-1][0], np.array([*scenario.goal, poses[-1][1][2]])))
        pieces = _pieces(formations, checkers, poses, rng)
    return LatticeResult(pieces, grid.spacing, nk, total, bool(expanded > expansions),
                         tuple(refused), float(best))


def _pieces(forms: list[Formation], checkers: list[PoseChecker],
            poses: list[tuple[int, np.ndarray]], rng: np.random.Generator) -> list[Piece]:
    """Rigid pieces (shortened) and changes along a path of (layer, pose)."""
    pieces: list[Piece] = []
    run: list[np.ndarray] = []
    layer = poses[0][0]
    for L, q in poses:
        if L != layer:
            pieces.append(_rigid(checkers[layer], forms[layer], run, rng))
            pieces.append(Piece(forms[layer], pieces[-1].waypoints[-1:], forms[L]))
            layer, run = L, []
        run.append(q)
    pieces.append(_rigid(checkers[layer], forms[layer], run, rng))
    return pieces


def _rigid(checker: PoseChecker, f: Formation, run: list[np.ndarray],
           rng: np.random.Generator) -> Piece:
    """A rigid piece through ``run``, merged and shortcut
    (:func:`~taut.plan.se2._rigid.merge_straight`)."""
    return Piece(f, merge_straight(checker, run, rng))
