"""Random feasible teams, for tests, benchmarks and sweeps (seeded, reproducible)."""

from __future__ import annotations

import numpy as np

from .._validate import MAX_ROBOTS, MAX_SHEET_LENGTH, as_array, as_bounded, as_count, require_instance
from ..errors import InvalidInputError
from .model import Sheet
from .team import SheetTeam

#: Draws :func:`random_hanging_team` makes before it gives up.
HANGING_DRAWS = 1000

__all__ = ["random_convex_polygon", "random_team", "random_scattered_team",
           "random_hanging_team"]


def random_convex_polygon(n: int, rng: np.random.Generator, *, radius: float = 1.0
                          ) -> np.ndarray:
    """``n`` points in convex position, counter-clockwise, shape (n, 2).

    Vertices on a random ellipse (semi-axes in ``[0.6, 1.0] * radius``, random tilt) at
    jittered, evenly spread angles, so no two vertices nearly coincide.
    """
    n = as_count(n, "n", minimum=3, maximum=MAX_ROBOTS)
    require_instance(rng, np.random.Generator, "rng")
    radius = as_bounded(radius, "radius", MAX_SHEET_LENGTH, "sheet units")
    base = 2 * np.pi * np.arange(n) / n
    t = base + rng.uniform(-0.35, 0.35, n) * (2 * np.pi / n) + rng.uniform(0, 2 * np.pi)
    a, b = radius * rng.uniform(0.6, 1.0, 2)
    tilt = rng.uniform(0, np.pi)
    c, s = np.cos(tilt), np.sin(tilt)
    pts = np.column_stack([a * np.cos(t), b * np.sin(t)])
    return pts @ np.array([[c, s], [-s, c]])


def random_team(n: int, rng: np.random.Generator, *, slack: tuple[float, float] = (0.55, 0.95)
                ) -> tuple[Sheet, np.ndarray]:
    """A random sheet and a random feasible formation for it.

    The formation is an independent random convex polygon (robot ``i`` near the
    direction of vertex ``i``), scaled so that every pair of robots is closer than
    its sheet vertices by a random factor in ``slack`` (FK paper's FormationFeasible),
    then moved by a random offset. Generic: lifted points in general position.

    Returns
    -------
    sheet : Sheet
    formation : ndarray, shape (n, 2)
    """
    slack = _slack(slack)
    V = random_convex_polygon(n, rng)
    R = random_convex_polygon(n, rng)
    # Keep robot i roughly "behind" vertex i: rotate R's first vertex onto V's.
    ang = np.arctan2(V[0, 1], V[0, 0]) - np.arctan2(R[0, 1], R[0, 0])
    c, s = np.cos(ang), np.sin(ang)
    R = R @ np.array([[c, s], [-s, c]])
    iu, ju = np.triu_indices(n, 1)
    ratio = np.linalg.norm(V[iu] - V[ju], axis=1) / np.linalg.norm(R[iu] - R[ju], axis=1)
    R = R * ratio.min() * rng.uniform(*slack) + rng.normal(scale=0.3, size=2)
    return Sheet(V), R


def random_scattered_team(n: int, rng: np.random.Generator,
                          *, slack: tuple[float, float] = (0.55, 0.95)
                          ) -> tuple[Sheet, np.ndarray]:
    """A random sheet and robots scattered anywhere (not in convex position, in any order),
    scaled to be feasible: the harder, less regular case for FK algorithms.

    Returns
    -------
    sheet : Sheet
    formation : ndarray, shape (n, 2)
    """
    slack = _slack(slack)
    V = random_convex_polygon(n, rng)
    R = rng.normal(size=(n, 2))
    iu, ju = np.triu_indices(n, 1)
    ratio = np.linalg.norm(V[iu] - V[ju], axis=1) / np.linalg.norm(R[iu] - R[ju], axis=1)
    R = R * ratio.min() * rng.uniform(*slack) + rng.normal(scale=0.3, size=2)
    return Sheet(V), R


def random_hanging_team(rng: np.random.Generator, *, robots: tuple[int, int] = (3, 8),
                        width: tuple[float, float] = (500.0, 1000.0),
                        hold: tuple[float, float] = (0.8, 1.5)
                        ) -> tuple[SheetTeam, np.ndarray]:
    """A random team for which forward kinematics finds an equilibrium: the sample of the
    physics checks.

    Draws ``n`` in ``robots`` (inclusive) and :func:`random_team`, scales it so that the
    sheet's longest side is uniform in ``width`` (sheet units), holds it at a height
    uniform in ``hold`` times the sheet radius (largest vertex distance from the vertices'
    centroid), and draws again until forward kinematics finds an equilibrium. The
    equilibrium may be unstable (about 1 % of draws have no stable one: the physics checks
    then verify that nothing is held).

    Returns
    -------
    team : SheetTeam
    formation : ndarray, shape (n, 2)

    Raises
    ------
    InvalidInputError
        A bad range, or no team with an equilibrium in :data:`HANGING_DRAWS` draws.
    """
    from .fk.forward import forward_kinematics

    require_instance(rng, np.random.Generator, "rng")
    if not isinstance(robots, (tuple, list)) or len(robots) != 2:
        raise InvalidInputError("robots", f"must be (low, high), got {robots!r}")
    lo_n, hi_n = (as_count(v, "robots", minimum=3, maximum=MAX_ROBOTS) for v in robots)
    w = _range(width, "width", MAX_SHEET_LENGTH)
    h = _range(hold, "hold", MAX_SHEET_LENGTH)
    if lo_n > hi_n:
        raise InvalidInputError("robots", f"must be (low, high) with low <= high, got "
                                          f"({lo_n}, {hi_n})")
    for _ in range(HANGING_DRAWS):
        n = int(rng.integers(lo_n, hi_n + 1))
        sheet, R = random_team(n, rng)
        scale = rng.uniform(*w) / float(np.max(sheet.side_lengths()))
        sheet, R = Sheet(sheet.vertices * scale), R * scale
        radius = float(np.max(np.linalg.norm(sheet.vertices - sheet.vertices.mean(0), axis=1)))
        team = SheetTeam(sheet, rng.uniform(*h) * radius)
        if forward_kinematics(team, R).equilibria:
            return team, R
    raise InvalidInputError("hold", f"no team with an equilibrium in {HANGING_DRAWS} draws")


def _range(value: object, field: str, limit: float) -> tuple[float, float]:
    """``value`` as ``(low, high)`` with 0 < low <= high <= ``limit``."""
    lo, hi = as_array(value, field, shape=(2,))
    if not 0.0 < lo <= hi <= limit:
        raise InvalidInputError(field, f"must be (low, high) with 0 < low <= high <= "
                                       f"{limit:g}, got ({lo:g}, {hi:g})")
    return float(lo), float(hi)


def _slack(slack: object) -> tuple[float, float]:
    """``slack`` as ``(low, high)`` with 0 < low <= high < 1 (a feasible formation)."""
    lo, hi = as_array(slack, "slack", shape=(2,))
    if not 0.0 < lo <= hi < 1.0:
        raise InvalidInputError("slack", f"must be (low, high) with 0 < low <= high < 1, got "
                                         f"({lo:g}, {hi:g})")
    return float(lo), float(hi)
