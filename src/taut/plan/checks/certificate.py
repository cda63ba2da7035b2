"""Certificates that no plan exists (issue 14, our construction).

A *cut certificate* is a straight line :math:`\\Sigma` that separates start and goal and
that no robot can cross and the sheet cannot pass. Proof, for any motion of any formation:

* each point of :math:`\\Sigma` inside the free space lies in an obstacle too tall for the
  sheet (height + height safety >= holding height: the object hangs below the hands, so
  such an obstacle can never be under the sheet) or in a *gap* narrower than
  ``2 (robot_radius + lateral_safety)`` between such obstacles and walls. No robot centre
  can be on :math:`\\Sigma` (it would be closer than the clearance to an end of its gap, or
  on an obstacle), so every robot stays on its side of :math:`\\Sigma`;
* if every robot is on the start side, the robots' convex hull (which holds the object) is
  in that half-plane and the object never reaches the goal; likewise on the goal side;
* if robots are on both sides, the hull (convex, in the free space, clear of the tall
  obstacles) meets :math:`\\Sigma` only inside one gap; every point of the hull, the object
  included, is then within the hull's diameter, at most the sheet's diameter, of that gap.
  The certificate requires start and goal farther than that from :math:`\\Sigma`.

Candidate lines pass through each tall obstacle's centre (72 directions) and through
points along the start-goal segment (perpendicular to it and 72 directions).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from shapely.geometry import LineString, Point
from shapely.ops import unary_union

from .. import _tol
from ..world import Scenario
from ..._validate import as_count, require_instance
from ..._repr import CompactRepr

__all__ = ["Certificate", "find_certificate"]


@dataclass(frozen=True, eq=False, repr=False)
class Certificate(CompactRepr):
    """Proof that no plan exists (see module docstring).

    Attributes
    ----------
    kind : {"cut"}
    line : ndarray, shape (2, 2)
        Two points of the cut line, m.
    obstacles : tuple of str
        The tall obstacles on the line.
    widest_gap : float
        Widest free gap along the line, m (< ``2 * clearance``).
    message : str
        The proof in one sentence.
    """

    kind: str
    line: np.ndarray
    obstacles: tuple[str, ...]
    widest_gap: float
    message: str


def _tall(scenario: Scenario) -> list:
    team = scenario.team
    return [o for o in scenario.world.obstacles
            if o.height + team.height_safety >= team.hold_height]


def _check_line(scenario: Scenario, p: np.ndarray, u: np.ndarray, tall: list
                ) -> Certificate | None:
    world, team = scenario.world, scenario.team
    V = team.sheet.vertices
    diameter = float(np.max(np.linalg.norm(V[:, None] - V[None], axis=-1)))
    n = np.array([-u[1], u[0]])
    ds, dg = float(np.dot(scenario.start - p, n)), float(np.dot(scenario.goal - p, n))
    if ds * dg >= 0 or min(abs(ds), abs(dg)) <= diameter:
        return None
    span = 4 * float(np.ptp(world.free_space, axis=0).max()) + 1.0
    line = LineString([p - span * u, p + span * u])
    inside = line.intersection(world.geometry)
    blockers = unary_union([o.geometry for o in tall]) if tall else None
    free = inside.difference(blockers) if blockers is not None else inside
    pieces = [g for g in getattr(free, "geoms", [free]) if not g.is_empty]
    widest = max((g.length for g in pieces), default=0.0)
    if widest >= 2 * team.clearance:
        return None
    used = tuple(o.id for o in tall if o.geometry.intersects(line))
    what = (f"obstacles {', '.join(repr(i) for i in used)} (too tall for the sheet)"
            if used else "the walls")
    msg = (f"no plan exists: the line through ({p[0]:.3g}, {p[1]:.3g}) at "
           f"{np.degrees(np.arctan2(u[1], u[0])):.0f} deg separates start and goal; along it "
           f"{what} leave gaps of at most {widest:.3g} m, narrower than a robot with its "
           f"lateral safety ({2 * team.clearance:.3g} m), and start and goal are farther "
           f"than the sheet's diameter ({diameter:.3g} m) from it")
    return Certificate("cut", np.array([p, p + u]), used, float(widest), msg)


def find_certificate(scenario: Scenario, directions: int = 72) -> Certificate | None:
    """A cut certificate (module docstring) when one of the candidate lines is one.

    Parameters
    ----------
    scenario : Scenario
    directions : int
        Candidate line directions through each anchor point (1 to 100000).

    Returns
    -------
    Certificate or None
    """
    require_instance(scenario, Scenario, "scenario")
    return _find_certificate(scenario, as_count(directions, "directions", minimum=1,
                                                maximum=100_000))


def _find_certificate(scenario: Scenario, directions: int = 72) -> Certificate | None:
    """:func:`find_certificate` on validated inputs."""
    tall = _tall(scenario)
    a = np.pi * np.arange(directions) / directions
    dirs = np.column_stack([np.cos(a), np.sin(a)])
    seg = scenario.goal - scenario.start
    anchors = [o.mec_center for o in tall]
    anchors += [scenario.start + s * seg for s in np.linspace(0.1, 0.9, 17)]
    along = seg / max(float(np.linalg.norm(seg)), _tol.SAME_POINT)
    for p in anchors:
        if not scenario.world.geometry.intersects(Point(p)):
            continue
        for u in [np.array([-along[1], along[0]]), *dirs]:
            cert = _check_line(scenario, np.asarray(p, float), u, tall)
            if cert is not None:
                return cert
    return None


def narrowest_cut(scenario: Scenario, blockers: list, directions: int = 72
                  ) -> tuple[float, str] | None:
    """Diagnosis for a failed search (not a proof): over lines through each obstacle of
    ``blockers`` (obstacles no formation of the library can cross) that separate start and
    goal, the least widest free gap along the line, m, treating ``blockers`` as walls, and
    the obstacle it passes through; None when no such line separates start and goal.

    A team whose narrowest formation needs more than this passage cannot get past with the
    library's formations; a narrower formation outside the library is not ruled out.
    """
    world = scenario.world
    span = 4 * float(np.ptp(world.free_space, axis=0).max()) + 1.0
    walls = unary_union([o.geometry for o in blockers]) if blockers else None
    a = np.pi * np.arange(directions) / directions
    best: tuple[float, str] | None = None
    for o in blockers:
        p = np.asarray(o.mec_center, float)
        for u in np.column_stack([np.cos(a), np.sin(a)]):
            n = np.array([-u[1], u[0]])
            if np.dot(scenario.start - p, n) * np.dot(scenario.goal - p, n) >= 0:
                continue
            line = LineString([p - span * u, p + span * u]).intersection(world.geometry)
            free = line.difference(walls) if walls is not None else line
            widest = max((g.length for g in getattr(free, "geoms", [free]) if not g.is_empty),
                         default=0.0)
            if best is None or widest < best[0]:
                best = (float(widest), str(o.id))
    return best
