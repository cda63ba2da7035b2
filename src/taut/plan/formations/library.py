"""The formation library of the SE(2) planner: the compact formation, the narrow one, the
optimal crossing formation per obstacle-height class (planning paper eqs. 11-15), a
squeezed formation (some cables slack) where passages are too narrow for all of them, and
the diagnosis of a failed search.
"""

from __future__ import annotations

import functools

import numpy as np

from .. import _tol
from ...sheet import FKSolver
from ._squeezed import _squeezed_formation
from ._squeeze_robust import tolerates
from ..checks.certificate import narrowest_cut
from .optimal import MIN_DEPTH_FRACTION, Formation, _optimal_formation
from ..result import compact_formation
from ..world import Scenario
from ..._validate import as_bounded, require_instance
from .._tol import MAX_SHEET_MARGIN_M

__all__ = ["formation_library"]

#: Most obstacle-height classes for which a crossing formation is optimised.
MAX_CLASSES = 4

def _height_classes(scenario: Scenario) -> list[float]:
    heights = sorted({o.height for o in scenario.world.obstacles})
    if len(heights) > MAX_CLASSES:
        idx = np.unique(np.linspace(0, len(heights) - 1, MAX_CLASSES).round().astype(int))
        heights = [heights[i] for i in idx]
    return heights


def _why_not_crossable(scenario: Scenario, h: float, ids: str) -> str:
    team = scenario.team
    if h + team.height_safety >= (1 - MIN_DEPTH_FRACTION) * team.hold_height:
        why = (f"the object hangs below the hands ({team.hold_height:.3g} m), so it "
               f"cannot clear {h:.3g} m plus the height safety")
    else:
        why = ("no stable all-taut formation lifts the object that high with room "
               "between the robots")
    return f"obstacle {ids} ({h:.3g} m tall) cannot be crossed: {why}"


def formation_library(scenario: Scenario, *, sheet_margin: float = 0.0) -> Library:
    """The formation library of the SE(2) planner for ``scenario``.

    Parameters
    ----------
    scenario : Scenario
    sheet_margin : float
        Every robot pair stays this far inside its sheet distance, m.

    Returns
    -------
    compact : Formation
        The most compact stable all-taut formation.
    others : list of Formation
        The narrow one when it differs, and the crossing formations, one per
        obstacle-height class (eqs. 11-15), preferring one that fits the widest passage.
    notes : list of str
        Why some height classes have no crossing formation.

    Raises
    ------
    PlanningError
        The team cannot hold the object at all.
    """
    require_instance(scenario, Scenario, "scenario")
    margin = as_bounded(sheet_margin, "sheet_margin", MAX_SHEET_MARGIN_M, "m", positive=False)
    return _formation_library(scenario, margin)


def _formation_library(scenario: Scenario, sheet_margin: float) -> Library:
    """:func:`formation_library` on validated inputs."""
    world, team = scenario.world, scenario.team
    compact = compact_formation(scenario, sheet_margin)
    crossing, notes = [], []
    # Triangles use the compact formation: their narrow one (least width, object at the
    # height safety) lost the object under 5 mm of position error on all 26 triangles of
    # the two benchmark suites (seeds 2024 and 5000), e.g. 0.368 m against 0.486 m wide.
    narrow = None if team.n <= 3 else _optimal_formation(team, "narrow", width=world.width,
                                                         sheet_margin=sheet_margin)
    if (narrow is not None and _min_width(narrow) < _min_width(compact) - _tol.NARROWER_BY
            and _robust(team, narrow)):
        crossing.append(narrow)
    for h in _height_classes(scenario):
        group = [o for o in world.obstacles if o.height <= h]
        diameter = max(o.diameter for o in group)
        f = _optimal_formation(team, "crossing", height=h, diameter=diameter,
                               width=world.width, max_reach=0.49 * world.width,
                               sheet_margin=sheet_margin)
        if f is None:
            f = _optimal_formation(team, "crossing", height=h, diameter=diameter,
                                   width=world.width, sheet_margin=sheet_margin)
        ids = ", ".join(repr(o.id) for o in group if o.height == h)
        if f is None:
            notes.append(_why_not_crossable(scenario, h, ids))
        elif not _robust(team, f):
            notes.append(f"obstacle {ids} ({h:.3g} m tall) cannot be crossed: the formation "
                         f"lifting the object to {f.object_height:.3g} m loses it under "
                         f"{_tol.POSITION_ACCURACY * 1e3:g} mm of robot position error (the "
                         "sheet is nearly flat)")
        else:
            crossing.append(f)
    return compact, crossing, notes


def _robust(team, f: Formation) -> bool:
    """Does the all-taut formation ``f``'s rest state survive the robots' position error
    (a stable state above the ground after each of ``LIBRARY_DRAWS`` seeded errors of up to
    5 mm, :func:`~taut.plan.formations._squeeze_robust.tolerates`)? A formation holding the object
    with the sheet nearly flat (every pair near its sheet distance) loses it under some.
    (Squeezed formations pass a stricter form of this check when they are designed.)"""
    solver = FKSolver(team.carrier)
    fk = solver.solve(np.ascontiguousarray(f.robots, dtype=float)).stable
    e = min(fk, key=lambda e: abs(e.height - f.object_height))
    return tolerates(solver, np.asarray(f.robots, dtype=float), e, 0.0, max_shift=np.inf)


Library = tuple[Formation, list[Formation], list[str]]


@functools.lru_cache(maxsize=32)
def _library(scenario: Scenario, sheet_margin: float
             ) -> tuple[Formation, tuple[Formation, ...], tuple[str, ...]]:
    """:func:`formation_library`, memoised per scenario object (the optimisations of
    eqs. 11-15 dominate a plan's time; baselines and re-plans reuse them)."""
    compact, others, notes = _formation_library(scenario, sheet_margin)
    return compact, tuple(others), tuple(notes)


def library(scenario: Scenario, sheet_margin: float) -> Library:
    """The memoised :func:`formation_library` (fresh lists the caller may extend)."""
    compact, others, notes = _library(scenario, sheet_margin)
    return compact, list(others), list(notes)


def _min_width(f: Formation) -> float:
    """Least width of the robots' hull over all directions, m."""
    a = np.linspace(0, np.pi, 180, endpoint=False)
    proj = f.robots @ np.stack([-np.sin(a), np.cos(a)])
    return float(np.ptp(proj, axis=0).min())


def _squeeze_width(scenario: Scenario, forms: list[Formation], allow_crossing: bool
                   ) -> float | None:
    """Width (m) a squeezed formation needs to pass beside the obstacles no formation of
    ``forms`` can cross (the narrowest cut's widest gap, less two clearances and
    ``SQUEEZE_ROOM``), or None when the narrowest formation of ``forms`` already fits
    there (or nothing blocks)."""
    cut = _blocking_cut(scenario, forms, allow_crossing)
    clearance = scenario.team.clearance
    if cut is None or cut[0] >= min(_min_width(f) for f in forms) + 2 * clearance:
        return None
    width = cut[0] - 2 * clearance - _tol.SQUEEZE_ROOM
    return width if width > 0 else None


@functools.lru_cache(maxsize=64)
def _squeezed(scenario: Scenario, sheet_margin: float, width: float) -> Formation | None:
    """:func:`~taut.plan.formations._squeezed.squeezed_formation` for ``width``, memoised."""
    return _squeezed_formation(scenario.team, sheet_margin, width)


def _with_squeezed(scenario: Scenario, forms: list[Formation], allow_crossing: bool,
                   sheet_margin: float) -> list[Formation]:
    """``forms`` and, where passages beside obstacles none of them can cross are too
    narrow for all of them, a squeezed formation (some cables slack) designed for the
    narrowest such passage."""
    width = _squeeze_width(scenario, forms, allow_crossing)
    f = None if width is None else _squeezed(scenario, sheet_margin, round(width, 6))
    if f is None or _min_width(f) >= min(_min_width(g) for g in forms) - _tol.NARROWER_BY:
        return forms
    return [*forms, f]


def _blocking_cut(scenario: Scenario, forms: list[Formation], allow_crossing: bool
                  ) -> tuple[float, str] | None:
    """The narrowest cut (its widest gap, m, and obstacle id) through the obstacles no
    formation of ``forms`` can cross (:func:`~taut.plan.checks.certificate.narrowest_cut`)."""
    top = max(f.max_height for f in forms) if allow_crossing else -np.inf
    blockers = [o for o in scenario.world.obstacles if o.height > top + _tol.GEOMETRY_TOL]
    return narrowest_cut(scenario, blockers)


def _diagnosis(scenario: Scenario, forms: list[Formation], allow_crossing: bool) -> str:
    """Why the search likely failed (not a proof): the narrowest passage beside obstacles
    no formation of the library can cross, against what the narrowest formation needs."""
    cut = _blocking_cut(scenario, forms, allow_crossing)
    if cut is None:
        return ""
    width = min(_min_width(f) for f in forms)
    need = width + 2 * scenario.team.clearance
    if cut[0] >= need:
        return ""
    return (f"diagnosis: on the narrowest line through obstacle {cut[1]!r} (which no "
            f"formation of the library can cross) the widest passage is {cut[0]:.3g} m, "
            f"less than the {need:.3g} m the narrowest formation found needs (its width "
            f"{width:.3g} m plus twice the clearance); a narrower formation "
            "outside the library is not ruled out")


